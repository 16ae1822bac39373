#!/usr/bin/env bash
# dem_step.sh: the DEM step of the campaign for one scenario and engine
# (rule dem of workflow/Snakefile).
#   dem_step.sh SCENARIO ENGINE SIZE NP RUNS STAMP   (RUNS: output root of run.sh)
# Runs scripts/dem/run.sh (which keeps finished runs whose deck and
# variables did not change), and on success (status ok, or complete but not
# steady: the data are usable and the scores say so) writes STAMP, a list of
# the runs' statuses, for Snakemake. On failure it names the log and exits
# with run.sh's status, so that Snakemake (--keep-going) carries on with the
# other scenarios. Exit codes: docs/exit-codes.md.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
[ $# -eq 6 ] || { echo "dem_step.sh: usage: dem_step.sh SCENARIO ENGINE SIZE NP RUNS STAMP" >&2; exit 1; }
scen=$1 engine=$2 size=$3 np=$4 runs=$5 stamp=$6
case $runs in /*) ;; *) runs=$PWD/$runs ;; esac
"$root/scripts/dem/run.sh" -n "$np" -o "$runs" "$scen" "$engine" "$size"
rc=$?
dir=$runs/$scen/$engine-$size
if [ $rc -ne 0 ] && [ $rc -ne 6 ]; then
  logs=$(grep -l '"status": "' "$dir"/run.json "$dir"/*/run.json 2>/dev/null | xargs -r grep -L '"status": "\(ok\|not_steady\)"' | sed 's/run.json$/screen.txt/' | tr '\n' ' ')
  echo "campaign: DEM FAILED: $scen $engine $size (run.sh exit $rc); log: ${logs:-$dir}" >&2
  rm -f "$stamp"
  exit $rc
fi
[ $rc -eq 6 ] && echo "campaign: note: $scen $engine $size finished but not steady (run.json); scored anyway" >&2
mkdir -p "$(dirname "$stamp")"
{ for j in "$dir"/run.json "$dir"/*/run.json; do
    if [ -f "$j" ]; then echo "$j: $(grep -o '"status": "[a-z_]*"' "$j")"; fi
  done; } > "$stamp.tmp" && mv "$stamp.tmp" "$stamp"
