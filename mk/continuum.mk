# mk/continuum.mk: ekm targets (included by the top-level Makefile).
#
#   make fuzz-scenario  fuzz the scenario reader and --set parsing for
#                       FUZZ_SECONDS (default 3600) with clang's libFuzzer +
#                       ASan/UBSan (fuzz/fuzz_scenario.c); new inputs go to
#                       fuzz/corpus_scenario

FUZZ_SECONDS ?= 3600

.PHONY: fuzz-scenario

fuzz-scenario:
	@scripts/deps.sh compare
	fuzz/run.sh --target scenario $(FUZZ_SECONDS) $(BUILD)/fuzz_scenario
