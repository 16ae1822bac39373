# ekmbench: the user's front door. Wraps cmake/ctest; see README.md.
#
#   make            build (Release) into build/
#   make test       build, run every test; then again under ASan+UBSan
#   make demo       install missing packages, build, run the smoke campaign
#   make bench [ONLY=ekm2d,...]  benchmarks: prints a table, writes
#                   results/bench.{md,json}; ONLY: rerun those bench/*.sh alone
#   make campaign [SIZE=smoke|ref] [ENGINES="liggghts lammps"] [NP=n] [-jN]
#                   DEM, coarse-graining, EKM, scores, table, figures
#   make figures    the paper figures from existing campaign results
#   make thesis2d   the thesis's 2D cases (box filling, sand piles) by ekm,
#                   their figures and numbers into results/ekm2d/ (~40 min)
#   make dem SCENARIO=.. ENGINE=.. SIZE=..   one DEM run (docs/dem.md)
#   make format     apply the C style (.clang-format) to every C file
#
# Components add targets in mk/*.mk (DEM runs, comparison, campaign).

BUILD      ?= build
BUILD_SAN  ?= build-sanitize
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_ARGS ?=
EKM        := $(BUILD)/continuum/ekm

.PHONY: all build deps test test-release test-sanitize demo bench thesis2d clean help format

all: build

deps:
	@scripts/deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS)

build: $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

$(BUILD_SAN)/CMakeCache.txt:
	cmake -S . -B $(BUILD_SAN) -DCMAKE_BUILD_TYPE=Debug -DEKM_SANITIZE=ON $(CMAKE_ARGS)

test: deps test-release test-sanitize

test-release: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The sanitizer pass skips tests labelled 'dem' (they exercise the external
# DEM engines, not our code) and 'figures' (Python's matplotlib; their one
# call of our code, `ekm homog`, runs under the sanitizers in homog_cli).
test-sanitize: $(BUILD_SAN)/CMakeCache.txt
	cmake --build $(BUILD_SAN) -j $(JOBS)
	cd $(BUILD_SAN) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j $(JOBS) -LE 'dem|figures'

demo: deps build
	@JOBS=$(JOBS) scripts/demo.sh $(BUILD)

bench: deps build
	@scripts/bench.sh $(BUILD)

thesis2d: build
	@JOBS=$(JOBS) scripts/thesis2d.sh $(BUILD)

# Apply the project's C style (.clang-format) to every tracked C file.
format:
	git ls-files '*.c' '*.h' | xargs clang-format -i

clean:
	rm -rf $(BUILD) $(BUILD_SAN)

help:
	@sed -n '1,17p' Makefile

-include mk/*.mk
