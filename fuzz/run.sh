#!/usr/bin/env bash
# fuzz/run.sh: build the dump-reader fuzz target with clang's libFuzzer and
# ASan/UBSan, and fuzz for SECONDS (default 20; `make fuzz-compare` runs an
# hour). New interesting inputs go to fuzz/corpus (not committed; crashes found
# there become regression seeds in fuzz/seeds);
# a crash leaves crash-* files in OUTDIR and a non-zero exit.
# usage: fuzz/run.sh [SECONDS] [OUTDIR]   (exit 77 = skipped: no clang)
# env CORPUS: where new inputs go (default fuzz/corpus; ctest uses a scratch
# directory so that tests do not write into the source tree).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
secs=${1:-20}
out=${2:-$root/build/fuzz}
command -v clang > /dev/null || { echo "fuzz/run.sh: clang not installed (scripts/deps.sh compare): skipped" >&2; exit 77; }
corpus=${CORPUS:-$here/corpus}
mkdir -p "$out" "$corpus"
exe="$out/fuzz_dump"
clang -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -D_POSIX_C_SOURCE=200809L -I"$root/compare" -I"$root/common" \
  "$here/fuzz_dump.c" "$root/compare/dump.c" "$root/common/status.c" -lz -lm -o "$exe" 2> "$out/build.log" ||
  { cat "$out/build.log" >&2; echo "fuzz/run.sh: cannot build with libFuzzer: skipped" >&2; exit 77; }
seeds=$(mktemp -d)
trap 'rm -rf "$seeds"' EXIT
cp "$root"/tests/compare/fixtures/* "$here"/seeds/* "$seeds"/
cd "$out"
# libFuzzer exits when a listed corpus directory is missing: list only the
# ones that exist (fuzz/corpus is not in a fresh clone).
dirs=("$corpus")
[ "$corpus" != "$here/corpus" ] && [ -d "$here/corpus" ] && dirs+=("$here/corpus")
dirs+=("$seeds")
"$exe" -max_total_time="$secs" -max_len=65536 -timeout=10 -rss_limit_mb=2048 \
  -print_final_stats=1 "${dirs[@]}" 2> "$out/fuzz.log" || {
  tail -40 "$out/fuzz.log" >&2
  echo "fuzz/run.sh: the fuzzer found a problem (see $out/fuzz.log, crash-* in $out)" >&2
  exit 1
}
grep -E "stat::number_of_executed_units|Done" "$out/fuzz.log" | tail -2 >&2
