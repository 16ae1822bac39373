#!/usr/bin/env bash
# Campaign rows of `make bench` (issue 6): per scenario, the DEM wall time
# of each engine against the EKM's wall time for the same scenario (all
# sweep points summed; one run each, same machine), as a ratio. Read from
# the reference campaign's results (results/, committed; `make campaign
# SIZE=ref`), or results/smoke/ when there are none. Writes $OUT/campaign.json.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
res=$root/results size=ref
[ -s "$res/scores.json" ] || { res=$root/results/smoke size=smoke; }
if [ ! -s "$res/scores.json" ]; then
  echo "bench/campaign.sh: no campaign results (make campaign SIZE=ref or SIZE=smoke): no DEM/EKM rows" >&2
  echo '{"rows": [], "keys": {}}' > "$OUT/campaign.json"
  exit 0
fi
attr() { h5dump -a "/$2" "$1" 2>/dev/null | awk '/\(0\):/ { print $2; exit }'; }
rows=() keys=()
for sdir in "$res"/*/; do
  s=$(basename "$sdir")
  [ -f "$root/scenarios/$s.ini" ] || continue
  ekm_s=0 n=0
  for h in "$sdir"ekm.h5 "$sdir"*/ekm.h5; do
    [ -f "$h" ] || continue
    w=$(attr "$h" stats.wall_time_s)
    [ -n "$w" ] || { echo "bench/campaign.sh: $h: no attribute stats.wall_time_s (re-run the campaign)" >&2; exit 1; }
    ekm_s=$(awk -v a="$ekm_s" -v b="$w" 'BEGIN { printf "%.6g", a + b }'); n=$((n + 1))
  done
  [ $n -gt 0 ] || continue
  for e in liggghts lammps; do
    dem_s=0 m=0
    for j in "$sdir"dem_$e.json "$sdir"*/dem_$e.json; do
      [ -f "$j" ] || continue
      dem_s=$(awk -v a="$dem_s" -v b="$(jq .wall_time_s "$j")" 'BEGIN { printf "%.6g", a + b }'); m=$((m + 1))
    done
    [ $m -gt 0 ] || continue
    ratio=$(awk -v a="$dem_s" -v b="$ekm_s" 'BEGIN { printf "%.3g", (b > 0 ? a / b : 0) }')
    rows+=("$(jq -cn --arg b "$s ($size): $e wall time / EKM wall time ($n point(s); DEM ${dem_s} s, EKM ${ekm_s} s)" \
      --argjson v "$ratio" '{benchmark: $b, value: $v, unit: "x", target: null, status: "measured"}')")
    keys+=("$(jq -cn --arg k "dem_${e}_over_ekm_${s}" --argjson v "$ratio" '{($k): $v}')")
  done
done
printf '%s\n' "${rows[@]}" | jq -s --argjson keys "$(printf '%s\n' "${keys[@]}" | jq -s 'add // {}')" \
  '{rows: ., keys: $keys}' > "$OUT/campaign.json"
