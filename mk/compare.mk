# mk/compare.mk: ekmcompare targets (included by the top-level Makefile).
#
#   make test-compare   build and run ekmcompare's tests (ctest -L compare)
#   make fuzz-compare   fuzz the dump reader for FUZZ_SECONDS (default 3600)
#                       with clang's libFuzzer + ASan/UBSan; new inputs go
#                       to fuzz/corpus
#   make bench-cg       only the coarse-graining benchmark (bench/cg.sh)
#   make demo-compare   coarse-grain the shipped chute dumps (LIGGGHTS and
#                       LAMMPS smoke runs), score one engine against the
#                       other (the floor no model beats) and, if `ekm` is
#                       built, the EKM chute against the LAMMPS run

FUZZ_SECONDS ?= 3600

CG_FX  := tests/compare/fixtures
CG_OUT := $(BUILD)/demo-compare

.PHONY: test-compare fuzz-compare bench-cg demo-compare

test-compare: build
	cd $(BUILD) && ctest --output-on-failure -L compare -j $(JOBS)

fuzz-compare:
	@scripts/deps.sh compare
	fuzz/run.sh $(FUZZ_SECONDS) $(BUILD)/fuzz

bench-cg: build
	@mkdir -p $(BUILD)/bench
	BUILD=$(abspath $(BUILD)) OUT=$(abspath $(BUILD))/bench bash bench/cg.sh
	@cat $(BUILD)/bench/cg.json

demo-compare: build
	@mkdir -p $(CG_OUT)
	$(BUILD)/compare/ekmcompare cg $(CG_FX)/chute_liggghts_atoms.dump.gz --dt 1e-5 --types 1 \
	  --pairs $(CG_FX)/chute_liggghts_pairs.dump.gz \
	  --pair-columns 'c_pc[1],c_pc[2],c_pc[3],c_pc[4],c_pc[5],c_pc[6],c_pc[10],c_pc[11],c_pc[12]' \
	  -o $(CG_OUT)/chute_liggghts.h5
	$(BUILD)/compare/ekmcompare cg $(CG_FX)/chute_lammps_atoms.dump.gz --types 1 \
	  --pairs $(CG_FX)/chute_lammps_pairs.dump.gz \
	  --pair-columns 'c_pid[1],c_pid[2],c_pl[2],c_pl[3],c_pl[4]' -o $(CG_OUT)/chute_lammps.h5
	@echo "LAMMPS vs LIGGGHTS (chute smoke runs, t = 0.25..0.3 s):"
	$(BUILD)/compare/ekmcompare score --dem $(CG_OUT)/chute_lammps.h5 --ekm $(CG_OUT)/chute_liggghts.h5 \
	  -o $(CG_OUT)/score_engines.json
	@if [ -x $(EKM) ]; then \
	  $(EKM) run scenarios/chute.ini -o $(CG_OUT)/ekm_chute.h5 --quiet && \
	  echo "EKM vs LAMMPS (chute):" && \
	  $(BUILD)/compare/ekmcompare score --dem $(CG_OUT)/chute_lammps.h5 --ekm $(CG_OUT)/ekm_chute.h5 \
	    -o $(CG_OUT)/score_ekm.json; \
	else echo "demo-compare: $(EKM) not built, EKM score skipped"; fi
