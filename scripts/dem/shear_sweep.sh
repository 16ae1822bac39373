#!/usr/bin/env bash
# shear_sweep.sh: table of a simple_shear sweep, for docs/dem.md.
#
#   scripts/dem/shear_sweep.sh DIR      (DIR = runs/simple_shear/<engine>-<size>)
#
# For each point phi<p>-rate<r>/ (status ok): means over the last half of
# monitor.txt of P, shear stress sxz, mu = sxz/P and T, the inertial number
# I = rate d / sqrt(P/rho_p); then per phi the log-log slope of P and of sxz
# against the shear rate (Bagnold scaling: 2).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
dir=$1
printf "%-6s %-6s %10s %10s %7s %10s %8s\n" phi rate P_Pa sxz_Pa mu T_m2s2 I
for p in "$dir"/phi*-rate*/; do
  [ -f "$p/run.json" ] && grep -q '"status": "ok"' "$p/run.json" || { echo "skip $p (not ok)" >&2; continue; }
  tag=$(basename "$p"); phi=${tag#phi}; phi=${phi%%-*}; rate=${tag##*rate}
  d=$(awk '$1 == "d" { print $3 }' "$p/vars.txt"); rho=$(awk '$1 == "rho" { print $3 }' "$p/vars.txt")
  "$here/monitor_stats.sh" "$p" | awk -v phi="$phi" -v rate="$rate" -v d="$d" -v rho="$rho" '
    { v[NR] = $2 } END { P = v[1]; s = v[2]; T = v[4]
      printf "%-6s %-6s %10.4g %10.4g %7.3f %10.3g %8.4f\n", phi, rate, P, s, s / P, T, rate * d / sqrt(P / rho) }'
done | tee /dev/stderr | awk '
  { n[$1]++; x = log($2); lp = log($3); ls = log($4)
    sx[$1] += x; sxx[$1] += x * x; sp[$1] += lp; sxp[$1] += x * lp; ss[$1] += ls; sxs[$1] += x * ls }
  END { for (f in n) if (n[f] >= 2) {
    den = n[f] * sxx[f] - sx[f] ^ 2
    printf "phi %s: exponent of P vs rate %.3f, of sxz vs rate %.3f (%d rates)\n", f,
      (n[f] * sxp[f] - sx[f] * sp[f]) / den, (n[f] * sxs[f] - sx[f] * ss[f]) / den, n[f] } }' 2>&1
