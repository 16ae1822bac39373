#!/usr/bin/env bash
# shear_sweep.sh: table of a simple-shear sweep (volume-controlled
# simple_shear, points phi<p>-rate<r>, or pressure-controlled simple_shear_p,
# points p<P>-rate<r>), for docs/dem.md.
#
#   scripts/dem/shear_sweep.sh DIR      (DIR = runs/<scenario>/<engine>-<size>)
#
# For each point with status ok (or not_steady: flagged): means and block
# standard errors (monitor_stats.sh: last half of monitor.txt, 5 blocks) of
# phi (from the grains' actual volumes: the box's under pressure control; the
# set value times about 0.999 under volume control), the mean
# pressure P = -tr(sigma)/3, the normal stress Pzz = -szz, mu = sxz/P, the
# granular temperature T; the inertial number I = rate d / sqrt(P / rho_p);
# the runner's steadiness verdict and drift; the run's wall time and the CPU
# time of its engine (Loop time x CPU use, summed over the runs of the log:
# the wall time a free core would take). Then, per phi (volume control), the
# log-log slope of P and sxz against the rate (Bagnold scaling: 2).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
dir=$1
printf "%-14s %6s %6s %17s %17s %17s %15s %19s %8s %6s %7s %7s %7s\n" point phi rate P_Pa Pzz_Pa sxz_Pa mu T_m2s2 I steady drift wall_s cpu_s
for p in "$dir"/*-rate*/; do
  [ -f "$p/run.json" ] || continue
  st=$(sed -n 's/.*"status": "\([a-z_]*\)".*/\1/p' "$p/run.json")
  case $st in ok|not_steady) ;; *) echo "skip $p (status $st)" >&2; continue ;; esac
  tag=$(basename "$p"); rate=${tag##*rate}
  d=$(awk '$1 == "d" { print $3 }' "$p/vars.txt"); rho=$(awk '$1 == "rho" { print $3 }' "$p/vars.txt")
  phi=$(awk '$1 == "phi" { print $3 }' "$p/vars.txt")
  steady=$(sed -n 's/.*"steady": \([a-z]*\),.*/\1/p' "$p/run.json")
  drift=$(sed -n 's/.*"monitor_drift": \([^,]*\),.*/\1/p' "$p/run.json")
  wall=$(sed -n 's/.*"wall_time_s": \([0-9.]*\),.*/\1/p' "$p/run.json")
  cpu=$(awk '/^Loop time of/ { t = $4 } /% CPU use/ { c += t * $1 / 100 } END { printf "%.0f", c }' "$p/log.txt")
  "$here/monitor_stats.sh" "$p" | awk -v tag="$tag" -v phi="$phi" -v rate="$rate" -v d="$d" -v rho="$rho" \
      -v steady="$steady" -v drift="$drift" -v wall="$wall" -v cpu="$cpu" '
    { m[$1] = $2; e[$1] = $4 }
    END {
      if ("v_phig" in m) ph = sprintf("%.4f", m["v_phig"]); else ph = phi
      P = m["v_P"]
      printf "%-14s %6s %6s %9.4g +- %-5.2g %9.4g +- %-5.2g %9.4g +- %-5.2g %6.4f +- %-5.2g %9.3g +- %-7.2g %8.4g %6s %7s %7.0f %7s\n",
        tag, ph, rate, P, e["v_P"], m["v_Pzz"], e["v_Pzz"], m["v_sxz"], e["v_sxz"], m["v_fric"], e["v_fric"],
        m["v_Tg"], e["v_Tg"], rate * d / sqrt(P / rho), steady, drift, wall, cpu }'
done | tee /dev/stderr | awk '
  $1 ~ /^phi/ { f = $2; n[f]++; x = log($3); lp = log($4); ls = log($10)
    sx[f] += x; sxx[f] += x * x; sp[f] += lp; sxp[f] += x * lp; ss[f] += ls; sxs[f] += x * ls }
  END { for (f in n) if (n[f] >= 2) {
    den = n[f] * sxx[f] - sx[f] ^ 2
    printf "phi %s: exponent of P vs rate %.3f, of sxz vs rate %.3f (%d rates)\n", f,
      (n[f] * sxp[f] - sx[f] * sp[f]) / den, (n[f] * sxs[f] - sx[f] * ss[f]) / den, n[f] } }' 2>&1
