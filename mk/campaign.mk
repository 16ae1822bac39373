# The validation campaign (docs/campaign.md), on Snakemake
# (workflow/Snakefile). Included by the top-level Makefile.
#
#   make campaign [SIZE=smoke|ref] [ENGINES="liggghts lammps"] [NP=1] [-jN | JOBS=N]
#                 [SCENARIOS="simple_shear simple_shear_p"]
#        every scenario with [dem] and [compare] sections (or those of
#        SCENARIOS; the table keeps every scenario's row): DEM runs (both
#        engines), coarse-graining, the EKM run, scores, the score table and
#        the figures; results in results/ (SIZE=ref, committed) or
#        results/smoke/ (SIZE=smoke, the default; not committed)
#   make figures [SIZE=...]      only the figures, from existing results
#   RES=DIR, RUNS=DIR            other results / DEM-run folders (tests)
#   make campaign-table [SIZE=...]   print the score table
#   FROM_CG=1        take existing coarse-grained DEM files as they are (the
#                    committed reference results on a fresh clone, without
#                    their dumps): EKM runs, scores, table and figures only
#
# Snakemake decides what is redone (--rerun-triggers mtime --drop-metadata:
# as make, a step whose inputs, i.e. scenario file, deck, binaries, scripts,
# are newer than its outputs), resumes an interrupted campaign (--rerun-incomplete), runs
# independent steps in parallel (-j from make's -jN, or JOBS=N) and goes
# on after a failed step (--keep-going), which it reports with its log.

CAMPAIGN_SIZE = $(or $(SIZE),smoke)
ENGINES      ?= liggghts lammps
CAMPAIGN_NP   = $(or $(NP),1)
CAMPAIGN_RES  = $(abspath $(or $(RES),$(if $(filter ref,$(CAMPAIGN_SIZE)),results,results/smoke)))
CAMPAIGN_RUNS = $(abspath $(or $(RUNS),runs))
# jobs: JOBS=N, else make's -jN (in MAKEFLAGS inside a recipe), else 1
CAMPAIGN_JOBS = $${JOBS:-$$(echo " $$MAKEFLAGS" | sed -n 's/.* -[a-zA-Z]*j\([0-9][0-9]*\).*/\1/p')}
export FROM_CG
CAMPAIGN_ARGS = $(CAMPAIGN_SIZE) '$(ENGINES)' $(CAMPAIGN_NP) $(CAMPAIGN_RES) $(CAMPAIGN_RUNS) \
  $(abspath $(BUILD)) "$$j" '$(SCENARIOS)'

.PHONY: campaign campaign-deps campaign-table figures

campaign-deps:
	@scripts/deps.sh base compare dem figures campaign

# scripts/campaign/campaign.sh: stale temporaries removed, "everything is up
# to date" when there is nothing to do, else the steps, the table and the
# figures; exit status 1 if a step failed
campaign: campaign-deps build
	+@j=$(CAMPAIGN_JOBS); j=$${j:-1}; scripts/campaign/campaign.sh all $(CAMPAIGN_ARGS)

campaign-table: build
	+@j=$(CAMPAIGN_JOBS); j=$${j:-1}; scripts/campaign/campaign.sh table $(CAMPAIGN_ARGS)

figures: build
	@scripts/deps.sh figures campaign
	+@j=$(CAMPAIGN_JOBS); j=$${j:-1}; scripts/campaign/campaign.sh figures $(CAMPAIGN_ARGS)
