#!/usr/bin/env bash
# score_step.sh: one score of the campaign.
#   score_step.sh EKMCOMPARE SCENARIO SIZE DEM.h5 OTHER.h5 OUT.json
# OTHER is the EKM run, or a second engine's CG (engine against engine: the
# floor). Fields, time matching and coordinate shift from [compare].
set -uo pipefail
prog=score_step.sh
. "$(dirname "$0")/lib.sh"
[ $# -eq 6 ] || die "usage: score_step.sh EKMCOMPARE SCENARIO SIZE DEM.h5 OTHER.h5 OUT.json"
ekmc=$1 scen=$2 size=$3 dem=$4 other=$5 out=$6
ini=$root/scenarios/$scen.ini
engine=$(basename "$dem" .h5); engine=${engine#cg_}
fields=$(cmpkey "$ini" "$engine" "$size" fields) || exit 2
etime=$(cmpkey "$ini" "$engine" "$size" ekm_time interp) || exit 2
shift_m=$(cmpkey "$ini" "$engine" "$size" shift 0) || exit 2
# engine against engine: both coordinates are the DEM's own
case $(basename "$other") in cg_*) shift_m=0 ;; esac
case $etime in last|interp) ;; *) die "$ini: [compare] ekm_time: expected last or interp, got '$etime'" ;; esac
"$ekmc" score --dem "$dem" --ekm "$other" --fields "$fields" --ekm-time "$etime" \
  --shift "$shift_m" -o "$out" --quiet > /dev/null
