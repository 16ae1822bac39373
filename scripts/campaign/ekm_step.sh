#!/usr/bin/env bash
# ekm_step.sh: the EKM run of the campaign for one scenario (one point).
#   ekm_step.sh EKM SCENARIO "POINT VARS" OUT.h5
# POINT VARS are the sweep variables of the DEM point (scripts/dem/run.sh
# -l): chute "theta A" sets [gravity] angle; simple_shear "phi P rate R"
# sets [initial] phi and the wall speeds -+R L/2. Otherwise the scenario
# runs as it is.
set -uo pipefail
prog=ekm_step.sh
. "$(dirname "$0")/lib.sh"
[ $# -eq 4 ] || die "usage: ekm_step.sh EKM SCENARIO \"POINT VARS\" OUT.h5"
ekm=$1 scen=$2 pv=$3 out=$4
ini=$root/scenarios/$scen.ini
sets=()
set -f; set -- $pv; set +f
while [ $# -ge 2 ]; do
  case $1 in
    theta) sets+=(--set "gravity.angle=$2") ;;
    phi)   sets+=(--set "initial.phi=$2") ;;
    rate)  L=$(inikey "$ini" domain length) || die "$ini: [domain] length: missing"
           v=$(awk -v r="$2" -v L="$L" 'BEGIN { printf "%.10g", r * L / 2 }')
           sets+=(--set "top.velocity=$v" --set "bottom.velocity=-$v") ;;
    *) die "unknown sweep variable '$1' for scenario $scen" ;;
  esac
  shift 2
done
mkdir -p "$(dirname "$out")"
"$ekm" run "$ini" "${sets[@]}" -o "$out" --quiet
