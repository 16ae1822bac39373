#!/usr/bin/env bash
# Calibration rows of `make bench` (issue 12): the wall time of the two fits
# the campaign makes, on the committed reference CG data, with the
# campaign's own options (workflow/Snakefile fit_command):
#   rheology  ekmcompare fit --rheology on the simple_shear + simple_shear_p
#             points' LAMMPS cg files (closed-form homogeneous EKM)
#   chute     ekmcompare fit --scenario on results/calibration/chute/cases.json
#             (the EKM solved to steady in-process for every evaluation)
# Writes $OUT/fit.json.  The fits' outputs go to a temporary folder (the
# committed results/calibration/ are never touched).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
ekmc="$BUILD/compare/ekmcompare"
ekm="$BUILD/continuum/ekm"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$root"

key() { # key SCENARIO KEY: a resolved scenario value
  "$ekm" scenario "scenarios/$1.ini" --json | jq -r --arg k "$2" '.keys[$k].value'
}
now() { date +%s.%N; }

shopt -s nullglob
cgs=(results/simple_shear/*/cg_lammps.h5 results/simple_shear_p/*/cg_lammps.h5)
[ ${#cgs[@]} -gt 0 ] || { echo "bench/fit.sh: no reference cg files under results/simple_shear*/" >&2; exit 2; }
t0=$(now)
"$ekmc" fit --rheology "${cgs[@]}" --params "$(key simple_shear campaign.fit_params)" \
  --fields "$(key simple_shear campaign.fit_fields)" --start scenarios/simple_shear.ini \
  -o "$tmp/rheology.json" --ini "$tmp/rheology.ini" > "$tmp/rheology.log"
t1=$(now)
rheology_s=$(awk -v a="$t0" -v b="$t1" 'BEGIN{print b - a}')

cases=results/calibration/chute/cases.json
[ -f "$cases" ] || { echo "bench/fit.sh: $cases: missing (the committed chute calibration)" >&2; exit 2; }
t0=$(now)
"$ekmc" fit --scenario "$cases" --params "$(key chute campaign.fit_params)" \
  --fields "$(key chute campaign.fit_fields)" --start scenarios/chute.ini \
  -o "$tmp/chute.json" --ini "$tmp/chute.ini" > "$tmp/chute.log"
t1=$(now)
chute_s=$(awk -v a="$t0" -v b="$t1" 'BEGIN{print b - a}')
chute_evals=$(jq -r '.evaluations.count // empty' "$tmp/chute.json")

jq -n --argjson r "$rheology_s" --argjson c "$chute_s" --argjson n "${chute_evals:-null}" \
  --argjson np "${#cgs[@]}" '
  def st(v; lim): if v < lim then "pass" else "fail" end;
  {rows: [
    {benchmark: "rheology fit (\($np) simple-shear points, 5 parameters)", value: ($r * 1000 | round / 1000),
     unit: "s", target: "< 10 s", status: st($r; 10)},
    {benchmark: "chute fit (3 angles, eta0 and eps0, EKM to steady per evaluation\(if $n then ", \($n) evaluations" else "" end))",
     value: ($c * 100 | round / 100), unit: "s", target: "< 60 s", status: st($c; 60)}],
   keys: {"fit_wall_s.rheology": $r, "fit_wall_s.chute": $c, "fit_evaluations.chute": $n}}' > "$OUT/fit.json"
