# The validation campaign (issue 6; docs/campaign.md). Included by the
# top-level Makefile.
#
#   make campaign [SIZE=smoke|ref] [ENGINES="liggghts lammps"] [NP=1] [-jN]
#        every scenario with [dem] and [compare] sections: DEM runs (both
#        engines), coarse-graining, the EKM run, scores, the score table and
#        the figures; results in results/ (SIZE=ref, committed) or
#        results/smoke/ (SIZE=smoke, the default; not committed)
#   make figures [SIZE=...]      only the figures, from existing results
#   RES=DIR, RUNS=DIR            other results / DEM-run folders (tests)
#   make campaign-table [SIZE=...]   print the score table
#
# Each step is a make rule in a generated makefile (RES/.plan.mk, from
# scripts/campaign/plan.sh): a finished step is redone only when its inputs
# (scenario file, deck, binaries, scripts) changed, an interrupted campaign
# resumes, -jN runs independent steps in parallel, and a failed step is
# reported (with its log) while the rest goes on (make -k).

CAMPAIGN_SIZE = $(or $(SIZE),smoke)
ENGINES      ?= liggghts lammps
CAMPAIGN_NP   = $(or $(NP),1)
CAMPAIGN_RES  = $(or $(RES),$(if $(filter ref,$(CAMPAIGN_SIZE)),results,results/smoke))
CAMPAIGN_RUNS = $(or $(RUNS),runs)
CAMPAIGN_PLAN = $(CAMPAIGN_RES)/.plan.mk

.PHONY: campaign campaign-plan campaign-deps campaign-table figures

campaign-deps:
	@scripts/deps.sh base compare dem figures

campaign-plan:
	@mkdir -p $(CAMPAIGN_RES)
	@scripts/campaign/plan.sh $(CAMPAIGN_SIZE) $(CAMPAIGN_RES) "$(ENGINES)" $(CAMPAIGN_NP) $(BUILD) $(CAMPAIGN_RUNS) > $(CAMPAIGN_PLAN).tmp
	@if cmp -s $(CAMPAIGN_PLAN).tmp $(CAMPAIGN_PLAN); then rm $(CAMPAIGN_PLAN).tmp; \
	  else mv $(CAMPAIGN_PLAN).tmp $(CAMPAIGN_PLAN); fi

# Three passes: the steps (make -k: a failure does not stop the others), then
# the table and the figures from what exists (parsed again, so that they
# see the scores just made). Exit status 1 if any step failed.
campaign: campaign-deps build campaign-plan
	+@if $(MAKE) -s -q -f $(CAMPAIGN_PLAN) all && $(MAKE) -s -q -f $(CAMPAIGN_PLAN) table figures; then \
	  echo "make campaign: everything is up to date ($(CAMPAIGN_RES), SIZE=$(CAMPAIGN_SIZE))"; \
	  cat $(CAMPAIGN_RES)/scores.md; exit 0; fi; \
	t0=$$(date +%s); rc=0; \
	$(MAKE) -s -k -f $(CAMPAIGN_PLAN) all || rc=1; \
	$(MAKE) -s -f $(CAMPAIGN_PLAN) table || rc=1; \
	cat $(CAMPAIGN_RES)/scores.md; \
	$(MAKE) -s -f $(CAMPAIGN_PLAN) figures || rc=1; \
	echo "make campaign: SIZE=$(CAMPAIGN_SIZE) done in $$(( $$(date +%s) - t0 )) s: $(CAMPAIGN_RES)/scores.md, $(CAMPAIGN_RES)/figures/"; \
	[ $$rc -eq 0 ] || echo "make campaign: some steps FAILED (messages above; the table marks them missing)" >&2; \
	exit $$rc

campaign-table: campaign-plan
	+@$(MAKE) -s -f $(CAMPAIGN_PLAN) table && cat $(CAMPAIGN_RES)/scores.md

figures: campaign-plan
	@scripts/deps.sh figures
	+@$(MAKE) -s -f $(CAMPAIGN_PLAN) figures
