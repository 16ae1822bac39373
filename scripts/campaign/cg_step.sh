#!/usr/bin/env bash
# cg_step.sh: coarse-grain one DEM run (one sweep point) for the campaign.
#   cg_step.sh EKMCOMPARE SCENARIO ENGINE SIZE TAG RUNS OUT.h5
# Options from the scenario's [compare] cg_options, the time step from
# [dem] dt (LIGGGHTS dumps carry no time); the run's run.json is copied
# next to OUT as dem_<engine>.json (provenance, wall time).
set -uo pipefail
prog=cg_step.sh
. "$(dirname "$0")/lib.sh"
[ $# -eq 7 ] || die "usage: cg_step.sh EKMCOMPARE SCENARIO ENGINE SIZE TAG RUNS OUT.h5"
ekmc=$1 scen=$2 engine=$3 size=$4 tag=$5 runs=$6 out=$7
ini=$root/scenarios/$scen.ini
run=$runs/$scen/$engine-$size${tag:+/$tag}
[ -r "$run/atoms.dump" ] || { echo "$prog: $run/atoms.dump: no dump (did the DEM step run?)" >&2; exit 1; }
opts=$(cmpkey "$ini" "$engine" "$size" cg_options) || exit 2
dt=$(awk '$1 == "dt" { print $3 }' "$run/vars.txt")
[ -n "$dt" ] || { echo "$prog: $run/vars.txt: no dt" >&2; exit 1; }
mkdir -p "$(dirname "$out")"
set -f
# shellcheck disable=SC2086
"$ekmc" cg "$run/atoms.dump" --dt "$dt" $opts -o "$out" || exit 1
set +f
cp "$run/run.json" "$(dirname "$out")/dem_$engine.json"
