#!/usr/bin/env bash
# fuzz/run.sh: build a fuzz target with clang's libFuzzer and ASan/UBSan, and
# fuzz for SECONDS (default 20).  Targets:
#   dump      the ekmcompare dump reader (fuzz_dump.c; the default;
#             `make fuzz-compare` runs an hour); seeds: tests/compare/fixtures
#             and fuzz/seeds
#   scenario  the scenario reader and --set parsing (fuzz_scenario.c); seeds:
#             every scenarios/*.ini and tests/continuum/data/*.ini (copied
#             here with a first line of no --set, and once with a --set),
#             and fuzz/scenario_seeds
# New interesting inputs go to fuzz/corpus (dump) or fuzz/corpus_scenario
# (not committed; crashes found there become regression seeds in fuzz/seeds
# or fuzz/scenario_seeds); a crash leaves crash-* files in OUTDIR and a
# non-zero exit.
# usage: fuzz/run.sh [--target dump|scenario] [SECONDS] [OUTDIR] [-- LIBFUZZER_OPTION...]
#   (exit 77 = skipped: no clang)
# env CORPUS: where new inputs go (ctest uses a scratch directory so that
# tests do not write into the source tree).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
target=dump
if [ "${1:-}" = --target ]; then
    target=${2:?--target needs dump or scenario}
    shift 2
fi
secs=${1:-20}
[ $# -gt 0 ] && shift
case $target in
    dump) out=${1:-$root/build/fuzz} ;;
    scenario) out=${1:-$root/build/fuzz_scenario} ;;
    *) echo "fuzz/run.sh: unknown target '$target' (expected dump or scenario)" >&2; exit 1 ;;
esac
[ $# -gt 0 ] && shift
[ "${1:-}" = -- ] && shift
extra=("$@")
command -v clang > /dev/null || { echo "fuzz/run.sh: clang not installed (scripts/deps.sh compare): skipped" >&2; exit 77; }
flags=(-g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined -D_POSIX_C_SOURCE=200809L)
seeds=$(mktemp -d)
trap 'rm -rf "$seeds"' EXIT
mkdir -p "$out"
if [ "$target" = dump ]; then
    corpus=${CORPUS:-$here/corpus}
    exe="$out/fuzz_dump"
    build=(clang "${flags[@]}" -I"$root/compare" -I"$root/common"
           "$here/fuzz_dump.c" "$root/compare/dump.c" "$root/common/status.c" -lz -lm -o "$exe")
    cp "$root"/tests/compare/fixtures/* "$here"/seeds/* "$seeds"/
    max_len=65536
else
    corpus=${CORPUS:-$here/corpus_scenario}
    exe="$out/fuzz_scenario"
    # the version string of the resolved JSON (cmake generates the real one)
    printf '#define EKMBENCH_VERSION "fuzz"\n' > "$out/ekm_version.h"
    build=(clang "${flags[@]}" -I"$root/scenario" -I"$root/law" -I"$root/common" -I"$out"
           "$here/fuzz_scenario.c" "$root"/scenario/{scenario,tool_keys,cg_keys,number,boundary,resolve,scenario_json}.c
           "$root"/law/model.c
           "$root"/common/{status,schema,utf8}.c -linih -ljansson -lm -o "$exe")
    # an input is "--set line" + the file: each shipped scenario without and
    # with an override
    for f in "$root"/scenarios/*.ini "$root"/tests/continuum/data/*.ini; do
        name=$(basename "$f" .ini)
        { echo; cat "$f"; } > "$seeds/$name"
        { echo "run.t_end=1"; cat "$f"; } > "$seeds/$name.set"
    done
    cp "$here"/scenario_seeds/* "$seeds"/
    max_len=16384
fi
mkdir -p "$corpus"
"${build[@]}" 2> "$out/build.log" ||
    { cat "$out/build.log" >&2; echo "fuzz/run.sh: cannot build with libFuzzer: skipped" >&2; exit 77; }
cd "$out"
# libFuzzer exits when a listed corpus directory is missing: list only the
# ones that exist (the committed corpus is not in a fresh clone).
dirs=("$corpus")
default_corpus=$here/corpus
[ "$target" = scenario ] && default_corpus=$here/corpus_scenario
[ "$corpus" != "$default_corpus" ] && [ -d "$default_corpus" ] && dirs+=("$default_corpus")
dirs+=("$seeds")
"$exe" -max_total_time="$secs" -max_len=$max_len -timeout=10 -rss_limit_mb=2048 \
  -print_final_stats=1 "${extra[@]}" "${dirs[@]}" 2> "$out/fuzz.log" || {
  tail -40 "$out/fuzz.log" >&2
  echo "fuzz/run.sh: the fuzzer found a problem (see $out/fuzz.log, crash-* in $out)" >&2
  exit 1
}
grep -E "stat::number_of_executed_units|Done" "$out/fuzz.log" | tail -2 >&2
