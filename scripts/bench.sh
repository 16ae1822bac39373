#!/usr/bin/env bash
# make bench: run every bench/*.sh (each writes one JSON fragment into
# $BUILD/bench/<name>.json: {"rows":[{"benchmark":..,"value":..,"unit":..,
# "target":..,"status":..}], "keys":{...}}), then merge the fragments into
# results/bench.json (flat keys + all rows) and results/bench.md (a table),
# and print the table.
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/$build/bench"
mkdir -p "$out" "$root/results"
# the temporaries go on every exit (an error under set -e, a signal); on a
# signal the status is 128+N
tmps=("$root/results/bench.json.tmp" "$root/results/bench.md.tmp")
trap 'rm -f "${tmps[@]}"' EXIT
for sig in INT TERM HUP; do
  n=$(kill -l "$sig")
  trap "rm -f \"\${tmps[@]}\"; trap - $sig EXIT; exit $((128 + n))" "$sig"
done
# ONLY=NAME[,NAME...] reruns those bench/NAME.sh alone and merges their
# fragments with the others' from the last run (a row set measured on a
# quiet machine after the whole run); the table's header says so
if [ -n "${ONLY:-}" ]; then
  IFS=, read -r -a names <<< "$ONLY"
  for n in "${names[@]}"; do
    [ -f "$root/bench/$n.sh" ] || { echo "bench: ONLY=$ONLY: no bench/$n.sh" >&2; exit 1; }
  done
  others=$(find "$out" -maxdepth 1 -name '*.json' | wc -l)
  [ "$others" -gt 0 ] || { echo "bench: ONLY=$ONLY: no fragments of a whole run in $out (run make bench first)" >&2; exit 1; }
  for n in "${names[@]}"; do
    echo "bench: running $n.sh alone" >&2
    BUILD="$root/$build" OUT="$out" bash "$root/bench/$n.sh"
  done
else
  rm -f "$out"/*.json
  for b in "$root"/bench/*.sh; do
    echo "bench: running $(basename "$b")" >&2
    BUILD="$root/$build" OUT="$out" bash "$b"
  done
fi
shopt -s nullglob
frags=("$out"/*.json)
[ ${#frags[@]} -gt 0 ] || { echo "bench: no results" >&2; exit 1; }
host="$(nproc) cores, $(awk '/model name/{sub(/.*: /,"");print;exit}' /proc/cpuinfo)"
ver=$(git -C "$root" describe --always --dirty 2>/dev/null || echo nogit)
jq -s --arg host "$host" --arg ver "$ver" --arg date "$(date -u +%Y-%m-%dT%H:%M:%SZ)" \
  '{date:$date, code_version:$ver, machine:$host,
    rows:(map(.rows)|add), keys:(map(.keys)|add)} + (map(.keys)|add)' \
  "${frags[@]}" > "$root/results/bench.json.tmp"
mv "$root/results/bench.json.tmp" "$root/results/bench.json"
{
  echo "# ekmbench benchmarks"
  echo
  if [ -n "${ONLY:-}" ]; then
    echo "Merged by \`make bench\` on $(jq -r .date "$root/results/bench.json"), code $ver, $host: the rows of ${ONLY//,/, } rerun alone (\`ONLY=$ONLY make bench\`), the others from the last whole run (results/bench.md of that run has its date and code)."
  else
    echo "Measured by \`make bench\` on $(jq -r .date "$root/results/bench.json"), code $ver, $host."
  fi
  echo
  echo "| benchmark | value | unit | target | status |"
  echo "|---|---:|---|---|---|"
  jq -r '.rows[] | "| \(.benchmark) | \(.value) | \(.unit) | \(.target // "") | \(.status // "") |"' \
    "$root/results/bench.json"
} > "$root/results/bench.md.tmp"
mv "$root/results/bench.md.tmp" "$root/results/bench.md"
cat "$root/results/bench.md"
