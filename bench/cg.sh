#!/usr/bin/env bash
# bench/cg.sh: ekmcompare coarse-graining throughput (particle-snapshots per
# second) on a 1e6-particle-snapshot dump (1e5 particles x 10 snapshots) as
# text, gzip and LAMMPS binary, side by side with a NumPy script doing the
# same binning (bench/cg_numpy.py, Debian's python3-numpy). Throughput is
# per core: particle-snapshots / CPU time (user + sys) of the process, best
# of 3 runs (the machine may be shared); the NumPy ratio uses the same
# measure in the same run. Writes $OUT/cg.json (see scripts/bench.sh).
# Env: BUILD (absolute build dir), OUT (fragment dir).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
: "${BUILD:?BUILD not set}" "${OUT:?OUT not set}"
ekmc="$BUILD/compare/ekmcompare"
synth="$BUILD/tests/compare/cg_synth"
py=/usr/bin/python3
for x in "$ekmc" "$synth"; do
  [ -x "$x" ] || { echo "bench/cg.sh: $x not built (make build)" >&2; exit 1; }
done
"$py" -c 'import numpy' 2>/dev/null ||
  { echo "bench/cg.sh: $py has no numpy (scripts/deps.sh compare)" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
natoms=100000 nsnap=10
n=$((natoms * nsnap))
"$synth" "$tmp/d.dump" text $natoms $nsnap
"$synth" "$tmp/d.dump.gz" gz $natoms $nsnap
"$synth" "$tmp/d.bin" bin $natoms $nsnap

# cpu_time CMD...: CPU seconds (user + sys) of one run
cpu_time() {
  local TIMEFORMAT='%U %S' t
  t=$( { time "$@" > /dev/null 2>&1; } 2>&1 ) || { echo "bench/cg.sh: failed: $*" >&2; exit 1; }
  awk -v t="$t" 'BEGIN { split(t, a, " "); printf "%.4f", a[1] + a[2] }'
}
best_of_3() {
  local best="" t
  for _ in 1 2 3; do
    t=$(cpu_time "$@")
    best=$(awk -v a="$t" -v b="$best" 'BEGIN { print (b == "" || a < b) ? a : b }')
  done
  echo "$best"
}
t_text=$(best_of_3 "$ekmc" cg "$tmp/d.dump" -o "$tmp/o.h5" --quiet)
t_gz=$(best_of_3 "$ekmc" cg "$tmp/d.dump.gz" -o "$tmp/o.h5" --quiet)
t_bin=$(best_of_3 "$ekmc" cg "$tmp/d.bin" -o "$tmp/o.h5" --quiet)
t_np=$(cpu_time "$py" "$here/cg_numpy.py" "$tmp/d.dump" text)

rate() { awk -v n="$n" -v t="$1" 'BEGIN { printf "%.4g", n / t }'; }
r_text=$(rate "$t_text"); r_gz=$(rate "$t_gz"); r_bin=$(rate "$t_bin"); r_np=$(rate "$t_np")
speedup=$(awk -v a="$t_np" -v b="$t_text" 'BEGIN { printf "%.3g", a / b }')
st_text=$(awk -v r="$r_text" 'BEGIN { print (r >= 3e6) ? "ok" : "MISSED" }')
st_speed=$(awk -v s="$speedup" 'BEGIN { print (s >= 5) ? "ok" : "MISSED" }')

jq -n --argjson rt "$r_text" --argjson rg "$r_gz" --argjson rb "$r_bin" --argjson rn "$r_np" \
  --argjson sp "$speedup" --arg st "$st_text" --arg ss "$st_speed" '{
  rows: [
    {benchmark: "ekmcompare cg, text dump (1e6 particle-snapshots)", value: $rt,
     unit: "particle-snapshots/s per core", target: ">= 3e6", status: $st},
    {benchmark: "ekmcompare cg, gzip dump", value: $rg,
     unit: "particle-snapshots/s per core", target: "", status: "ok"},
    {benchmark: "ekmcompare cg, LAMMPS binary dump", value: $rb,
     unit: "particle-snapshots/s per core", target: "", status: "ok"},
    {benchmark: "NumPy reference (loadtxt + bincount), text dump", value: $rn,
     unit: "particle-snapshots/s per core", target: "", status: "ok"},
    {benchmark: "ekmcompare speed-up over NumPy, text dump", value: $sp,
     unit: "x", target: ">= 5", status: $ss}
  ],
  keys: {cg_text_particles_per_s: $rt, cg_gz_particles_per_s: $rg,
         cg_binary_particles_per_s: $rb, cg_speedup_vs_numpy: $sp}
}' > "$OUT/cg.json.tmp"
mv "$OUT/cg.json.tmp" "$OUT/cg.json"
echo "bench/cg.sh: text $r_text/s, gz $r_gz/s, binary $r_bin/s, NumPy $r_np/s, speed-up ${speedup}x" >&2
