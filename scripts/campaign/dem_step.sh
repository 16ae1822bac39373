#!/usr/bin/env bash
# dem_step.sh: the DEM step of the campaign for one scenario and engine.
#   dem_step.sh SCENARIO ENGINE SIZE NP RUNS STAMP   (RUNS: output root of run.sh)
# Runs scripts/dem/run.sh (which keeps finished runs whose deck and
# variables did not change), and on success (status ok, or complete but not
# steady: the data are usable and the scores say so) writes STAMP, a list of
# the runs' statuses, for make. On failure it names the log and exits 1 so
# that make -k carries on with the other scenarios.
set -uo pipefail
prog=dem_step.sh
. "$(dirname "$0")/lib.sh"
[ $# -eq 6 ] || die "usage: dem_step.sh SCENARIO ENGINE SIZE NP RUNS STAMP"
scen=$1 engine=$2 size=$3 np=$4 runs=$5 stamp=$6
case $runs in /*) ;; *) runs=$PWD/$runs ;; esac
"$root/scripts/dem/run.sh" -n "$np" -o "$runs" "$scen" "$engine" "$size"
rc=$?
dir=$runs/$scen/$engine-$size
if [ $rc -ne 0 ] && [ $rc -ne 4 ]; then
  logs=$(grep -l '"status": "' "$dir"/run.json "$dir"/*/run.json 2>/dev/null | xargs -r grep -L '"status": "\(ok\|not_steady\)"' | sed 's/run.json$/screen.txt/' | tr '\n' ' ')
  echo "campaign: DEM FAILED: $scen $engine $size (run.sh exit $rc); log: ${logs:-$dir}" >&2
  rm -f "$stamp"
  exit 1
fi
[ $rc -eq 4 ] && echo "campaign: note: $scen $engine $size finished but not steady (run.json); scored anyway" >&2
mkdir -p "$(dirname "$stamp")"
{ for j in "$dir"/run.json "$dir"/*/run.json; do
    if [ -f "$j" ]; then echo "$j: $(grep -o '"status": "[a-z_]*"' "$j")"; fi
  done; } > "$stamp.tmp" && mv "$stamp.tmp" "$stamp"
