#!/usr/bin/env bash
# bench/steps.sh: steps per model second against the cell count (issue 12:
# the N^2 claim, before and after the implicit pressure coupling), for chute
# and shear_cell at 100, 1000 and 10000 cells, with [numerics]
# normal_coupling = explicit (before: the acoustic CFL, the step ~ 1/N) and
# implicit (after: convective CFL and the accuracy limits, docs/model/slab.md
# "Implicit pressure coupling"). Each run starts from the scenario's initial
# state and runs a fixed model time, the same for both couplings: 0.25 s at
# 100 and 1000 cells, 2 ms at 10000 cells (the explicit run at 10000 cells
# for 0.25 s would take minutes). Counts only (steps of `ekm run`), no wall
# times. Target: at least 10x fewer steps per model second at 1000 cells
# (issue 12). Writes $OUT/steps.json (see scripts/bench.sh).
# Env: BUILD (absolute build dir), OUT (fragment dir).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
: "${BUILD:?BUILD not set}" "${OUT:?OUT not set}"
ekm="$BUILD/continuum/ekm"
[ -x "$ekm" ] || { echo "bench/steps.sh: $ekm not built (make build)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# steps SCENARIO CELLS COUPLING T_WINDOW: the accepted steps of the run
steps() {
  local line
  line=$("$ekm" run "$root/scenarios/$1.ini" -o "$tmp/run.h5" --set "domain.cells=$2" \
    --set "run.t_end=$4" --set "run.output_dt=$4" --set run.stop=t_end \
    --set "numerics.normal_coupling=$3" 2>&1 | head -1)
  local n
  n=$(awk '{ for (i = 2; i <= NF; i++) if ($i == "steps") { print $(i - 1); exit } }' <<<"$line")
  [[ "$n" =~ ^[0-9]+$ ]] || { echo "bench/steps.sh: $1 at $2 cells ($3): no step count in: $line" >&2; exit 1; }
  echo "$n"
}

rows=() keys=()
for s in chute shear_cell; do
  for cells in 100 1000 10000; do
    window=0.25
    [ "$cells" -ge 10000 ] && window=0.002
    e=$(steps "$s" "$cells" explicit "$window")
    i=$(steps "$s" "$cells" implicit "$window")
    rate_e=$(awk -v n="$e" -v t="$window" 'BEGIN { printf "%.4g", n / t }')
    rate_i=$(awk -v n="$i" -v t="$window" 'BEGIN { printf "%.4g", n / t }')
    ratio=$(awk -v a="$e" -v b="$i" 'BEGIN { printf "%.3g", a / b }')
    target=null status=measured
    if [ "$cells" -eq 1000 ]; then
      target='">= 10x fewer (issue 12)"'
      status=$(awk -v r="$ratio" 'BEGIN { print (r >= 10 ? "met" : "missed") }')
    fi
    rows+=("$(jq -cn --arg b "steps per model second, $s, $cells cells, explicit coupling (before; first $window s)" \
      --argjson v "$rate_e" '{benchmark: $b, value: $v, unit: "steps/s", target: null, status: "measured"}')")
    rows+=("$(jq -cn --arg b "steps per model second, $s, $cells cells, implicit coupling (after; first $window s)" \
      --argjson v "$rate_i" '{benchmark: $b, value: $v, unit: "steps/s", target: null, status: "measured"}')")
    rows+=("$(jq -cn --arg b "fewer steps, implicit vs explicit coupling, $s, $cells cells (first $window s)" \
      --argjson v "$ratio" --argjson t "$target" --arg st "$status" \
      '{benchmark: $b, value: $v, unit: "x", target: $t, status: $st}')")
    keys+=("$(jq -cn --arg s "$s" --arg c "$cells" --argjson e "$rate_e" --argjson i "$rate_i" --argjson r "$ratio" \
      '{("steps_per_model_s.explicit.\($s).\($c)"): $e, ("steps_per_model_s.implicit.\($s).\($c)"): $i,
        ("steps_ratio.\($s).\($c)"): $r}')")
  done
done
printf '%s\n' "${rows[@]}" | jq -s --argjson keys "$(printf '%s\n' "${keys[@]}" | jq -s 'add // {}')" \
  '{rows: ., keys: $keys}' > "$OUT/steps.json"
