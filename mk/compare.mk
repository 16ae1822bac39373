# mk/compare.mk: ekmcompare targets (included by the top-level Makefile).
#
#   make test-compare   build and run ekmcompare's tests (ctest -L compare)
#   make fuzz-compare   fuzz the dump reader for FUZZ_SECONDS (default 3600)
#                       with clang's libFuzzer + ASan/UBSan; new inputs go
#                       to fuzz/corpus
#   make bench-cg       only the coarse-graining benchmark (bench/cg.sh)

FUZZ_SECONDS ?= 3600

.PHONY: test-compare fuzz-compare bench-cg

test-compare: build
	cd $(BUILD) && ctest --output-on-failure -L compare -j $(JOBS)

fuzz-compare:
	@scripts/deps.sh compare
	fuzz/run.sh $(FUZZ_SECONDS) $(BUILD)/fuzz

bench-cg: build
	@mkdir -p $(BUILD)/bench
	BUILD=$(abspath $(BUILD)) OUT=$(abspath $(BUILD))/bench bash bench/cg.sh
	@cat $(BUILD)/bench/cg.json
