# DEM runs (issue 3; docs/dem.md). Included by the top-level Makefile.
#
#   make dem SCENARIO=chute ENGINE=lammps SIZE=smoke [NP=1] [FORCE=1] [DEMSET="angles=24"]
#   make dem-all SIZE=smoke          every scenario in both engines
#   make dem-collision               binary-collision restitution check, both engines
#   make dem-calibrate ENGINE=...    bisect the engine's input restitution
#
# Output: runs/<scenario>/<engine>-<size>[/<point>]/ (dumps, log, deck,
# vars.txt, run.json). DEMSET overrides [dem] keys for one run.

DEM_SCENARIOS := filling shear_cell simple_shear simple_shear_p chute sandpile
DEM_ENGINES   := liggghts lammps
DEM_SIZE       = $(or $(SIZE),smoke)
DEM_FLAGS      = $(if $(filter 1,$(FORCE)),-f) -n $(or $(NP),1) $(foreach s,$(DEMSET),-s $(s))

.PHONY: dem dem-all dem-deps dem-tools dem-collision dem-calibrate

EKMSCENARIO := $(BUILD)/scenario/ekmscenario

# What the runner calls: ekmscenario (the resolved scenario) and ekmcompare
# (its `steady` judges a run's monitor series); not the ekm program.
dem-tools: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS) --target ekmscenario ekmcompare

dem-deps:
	@scripts/deps.sh dem

dem: dem-deps dem-tools
	@test -n "$(SCENARIO)" -a -n "$(ENGINE)" || \
	  { echo "usage: make dem SCENARIO=<$(DEM_SCENARIOS)> ENGINE=<$(DEM_ENGINES)> SIZE=<smoke|ref> [NP=n] [FORCE=1]" >&2; exit 1; }
	EKMSCENARIO=$(abspath $(EKMSCENARIO)) scripts/dem/run.sh $(DEM_FLAGS) $(SCENARIO) $(ENGINE) $(DEM_SIZE)

# Runs every case one after the other; unsupported pairs
# (dem_inputs/<engine>/<scenario>.unsupported) are skipped, any failure
# makes the target fail after all have run. run.sh reads the scenario
# through `ekmscenario --json`, hence `dem-tools`.
dem-all: dem-deps dem-tools
	@rc=0; for s in $(DEM_SCENARIOS); do for e in $(DEM_ENGINES); do \
	  [ -e dem_inputs/$$e/$$s.unsupported ] && continue; \
	  EKMSCENARIO=$(abspath $(EKMSCENARIO)) scripts/dem/run.sh $(DEM_FLAGS) $$s $$e $(DEM_SIZE) || rc=1; \
	done; done; exit $$rc

dem-collision: dem-deps dem-tools
	EKMSCENARIO=$(abspath $(EKMSCENARIO)) scripts/dem/collision.sh -o runs liggghts
	EKMSCENARIO=$(abspath $(EKMSCENARIO)) scripts/dem/collision.sh -o runs lammps

dem-calibrate: dem-deps dem-tools
	EKMSCENARIO=$(abspath $(EKMSCENARIO)) scripts/dem/collision.sh --calibrate -o runs $(or $(ENGINE),lammps)
