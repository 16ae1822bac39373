#!/usr/bin/env bash
# chute_profile.sh: steady-state profiles of a chute run, for docs/dem.md.
#
#   scripts/dem/chute_profile.sh [-w FRACTION] [-b BIN_D] [-s TSTART] DIR
#
# Reads DIR/atoms.dump and DIR/vars.txt; averages the frames of the last
# FRACTION (default 0.5) of the flow period (t_settle + t_flow), or, with
# -s, every frame from time TSTART on (any slab run, e.g. shear_cell). Profiles along the bed normal
# z (origin: centre plane of the base grains) in bins of BIN_D grain
# diameters (default 0.5): phi(z) from the exact sphere-slab intersection
# volumes, u(z) mass-weighted mean v_x of the grains centred in the bin.
# Summary: flow height h (phi falls to half its bulk value), bulk phi (mean
# over 0.2 h < z < 0.8 h), mean velocity, and the least-squares fit of
# u(z) = u_s [1 - (1 - z/h)^n] over 0.5 d < z < h.
# This is a quick check, not the coarse-graining tool (compare/).
set -euo pipefail
frac=0.5; bin=0.5; tstart=""
while getopts "w:b:s:" o; do case $o in w) frac=$OPTARG ;; b) bin=$OPTARG ;; s) tstart=$OPTARG ;; *) exit 1 ;; esac; done
shift $((OPTIND - 1))
[ $# -eq 1 ] || { echo "usage: chute_profile.sh [-w FRACTION] [-b BIN_D] [-s TSTART] DIR" >&2; exit 1; }
dir=$1
for f in vars.txt atoms.dump; do
  [ -r "$dir/$f" ] || { echo "chute_profile: $dir/$f: missing (a DEM run folder)" >&2; exit 3; }
done
v() { awk -v k="$1" '$1 == k { print $3 }' "$dir/vars.txt"; }
if [ -n "$tstart" ]; then t0=$tstart; tf=0; else t0=$(v t_settle); tf=$(v t_flow); fi
awk -v dt="$(v dt)" -v t0="$t0" -v tf="$tf" -v frac="$frac" \
    -v d="$(v d)" -v lx="$(v lx)" -v ly="$(v ly)" -v binw="$bin" '
function seg(a, b, r, zc,   lo, hi) {          # volume of sphere in slab [a,b]
  lo = (a > zc - r) ? a : zc - r; hi = (b < zc + r) ? b : zc + r
  if (hi <= lo) return 0
  return 3.141592653589793 * (r*r*(hi - lo) - ((hi - zc)^3 - (lo - zc)^3) / 3)
}
/^ITEM: TIMESTEP/ { getline; step = $1; use = (step * dt >= t0 + (1 - frac) * tf); inatoms = 0; if (use) nf++; next }
/^ITEM: ATOMS/ { for (i = 3; i <= NF; i++) col[$i] = i - 2; inatoms = 1; next }
/^ITEM:/ { inatoms = 0; next }
inatoms && use {
  if ($col["type"] != 1) next
  z = $col["z"]; r = $col["radius"]; m = $col["mass"]; u = $col["vx"]
  b = int(z / bw); if (b < 0) next
  mu[b] += m * u; ms[b] += m
  for (k = int((z - r) / bw); k <= int((z + r) / bw); k++) if (k >= 0) vol[k] += seg(k * bw, (k + 1) * bw, r, z)
  mt += m; mut += m * u
}
BEGIN { bw = binw * d }
END {
  if (nf == 0) { print "chute_profile: no frames in the averaging window" > "/dev/stderr"; exit 2 }
  A = lx * ly; nb = 0
  for (k in vol) if (k + 0 > nb) nb = k + 0
  for (k = 0; k <= nb; k++) { phi[k] = vol[k] / (A * bw * nf); uu[k] = (ms[k] > 0) ? mu[k] / ms[k] : 0 }
  # bulk phi: iterate h and bulk once (start from the max phi)
  pm = 0; for (k = 0; k <= nb; k++) if (phi[k] > pm) pm = phi[k]
  for (it = 0; it < 3; it++) {
    h = 0; for (k = 0; k <= nb; k++) if (phi[k] >= pm / 2) h = (k + 1) * bw
    s = 0; c = 0; for (k = 0; k <= nb; k++) { zc = (k + 0.5) * bw; if (zc > 0.2 * h && zc < 0.8 * h) { s += phi[k]; c++ } }
    if (c) pm = s / c
  }
  printf "# z/d phi u[m/s]   (%d frames)\n", nf
  for (k = 0; k <= nb; k++) printf "%6.2f %.4f %.4f\n", (k + 0.5) * bw / d, phi[k], uu[k]
  # fit n on a grid; for each n the best u_s is linear least squares
  best = 1e300
  for (n = 0.5; n <= 3.0001; n += 0.01) {
    sfu = 0; sff = 0
    for (k = 0; k <= nb; k++) { zc = (k + 0.5) * bw; if (zc < 0.5 * d || zc > h) continue
      f = 1 - (1 - zc / h)^n; sfu += f * uu[k]; sff += f * f }
    us = sfu / sff; e = 0
    for (k = 0; k <= nb; k++) { zc = (k + 0.5) * bw; if (zc < 0.5 * d || zc > h) continue
      f = 1 - (1 - zc / h)^n; e += (uu[k] - us * f)^2 }
    if (e < best) { best = e; bn = n; bus = us }
  }
  printf "SUMMARY h/d %.2f phi_bulk %.4f u_mean %.4f u_s %.4f n %.2f frames %d\n", h / d, pm, mut / mt, bus, bn, nf
}' "$dir/atoms.dump"
