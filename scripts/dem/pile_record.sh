#!/usr/bin/env bash
# pile_record.sh: the committed record of finished sand-pile runs (issue
# 34), so that the ensemble outlives the machine that ran it.
#
#   scripts/dem/pile_record.sh [-f] [-R RECORDS] -l LAW RUN_DIR...
#
# RUN_DIR is a run of scripts/dem/ensemble.sh sandpile,
# DIR/seed<k>/sandpile/<engine>-<size>/<point>/ (pile_rounds.sh: DIR is
# runs/pile/LAW), LAW plain or rolling (it must agree with the run's mu_r).
# A run that finished (run.json status ok) and passes
# `check_run.sh --sandpile` gets its record
# RECORDS/LAW/<engine>-<size>/<point>/seed<k>/ (RECORDS default
# results/sandpile/runs; commit it): `ekmcompare base --last 1` of its
# atoms.dump (base.h5, base.csv: the pile at rest on 2 d bins over the box,
# about its middle), map.h5 (`ekmcompare cg --axes x,z` of its last
# snapshot with the options of `pile_record.py mapargs`: the pile grains'
# phi and contact stress cxx czz cxz on 2 d cells over the box, from the
# plate's top to the box's top; docs/dem.md "The density and stress
# maps"), record.json (scripts/dem/pile_record.py make: the law, source,
# member, pile_summary.py's row, the surface on the base bins) and copies
# of run.json and vars.txt: about 35 kB. It is written into a hidden
# temporary directory beside it and renamed into place. A record that
# exists is kept (the member's seed is fixed: running it again makes no new
# pile), -f replaces it. scripts/dem/pile_analysis.sh reads the records.
# EKMCOMPARE= names the ekmcompare binary (default build/compare/ekmcompare).
# Exit status (docs/exit-codes.md): 0 every run recorded (or its record
# kept); 1 usage; 2 a run not laid out as above or not finished (status
# not ok); check_run.sh's status when the run fails its check (not
# recorded); otherwise ekmcompare's or pile_record.py's; 7 ekmcompare not
# built. Every run is tried; the first failure's status is returned.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
prog=pile_record.sh
usage() { echo "$prog: $*" >&2; exit 1; }
records=$root/results/sandpile/runs; law=""; force=()
while getopts "fR:l:h" opt; do
  case $opt in
    f) force=(-f) ;;
    R) records=$OPTARG ;;
    l) law=$OPTARG ;;
    h) sed -n '2,30p' "$0"; exit 0 ;;
    *) usage "bad option (see -h)" ;;
  esac
done
shift $((OPTIND - 1))
if [ $# -lt 1 ] || [ -z "$law" ]; then usage "usage: pile_record.sh [-f] [-R RECORDS] -l LAW RUN_DIR..."; fi
case $law in plain|rolling) ;; *) usage "-l: unknown law '$law' (plain, rolling)" ;; esac
ekmcompare=${EKMCOMPARE:-$root/build/compare/ekmcompare}
[ -x "$ekmcompare" ] || { echo "$prog: ekmcompare not built: run make build (no executable $ekmcompare)" >&2; exit 7; }

tmp=""
cleanup() { [ -z "$tmp" ] || rm -rf "$tmp"; }
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
trap 'exit 129' HUP

# record_run DIR: 0 recorded or kept, else the status
record_run() {
  local dir=${1%/} re='(^|/)seed([1-9][0-9]*)/sandpile/(lammps|liggghts)-([A-Za-z0-9_]+)/(source[0-9]+)$'
  if ! [[ $dir =~ $re ]]; then
    echo "$prog: $dir: expected a run DIR/seed<k>/sandpile/<engine>-<size>/<point> of ensemble.sh" >&2; return 2
  fi
  local k=${BASH_REMATCH[2]} engine=${BASH_REMATCH[3]} size=${BASH_REMATCH[4]} point=${BASH_REMATCH[5]}
  local rec=$records/$law/$engine-$size/$point/seed$k
  if [ -e "$rec" ] && [ ${#force[@]} -eq 0 ]; then
    echo "$prog: $dir: recorded already ($rec): kept"; return 0
  fi
  [ -f "$dir/run.json" ] || { echo "$prog: $dir/run.json: no such file (a finished run)" >&2; return 2; }
  grep -q '"status": "ok"' "$dir/run.json" ||
    { echo "$prog: $dir/run.json: expected status ok, got $(grep -o '"status": "[a-z_]*"' "$dir/run.json"): not recorded" >&2; return 2; }
  local chk r
  chk=$("$here/check_run.sh" --sandpile "$dir" 2>&1); r=$?
  if [ $r -ne 0 ]; then
    printf '%s\n' "$chk" >&2
    echo "$prog: $dir: check_run.sh --sandpile fails: not recorded" >&2; return $r
  fi
  mkdir -p "$(dirname "$rec")" || return 3
  tmp=$(mktemp -d "$(dirname "$rec")/.seed$k.tmp.XXXXXX") || return 3
  "$ekmcompare" base --last 1 --quiet -o "$tmp/base.h5" --csv "$tmp/base.csv" "$dir/atoms.dump" || { r=$?; cleanup; tmp=""; return $r; }
  local margs cgargs
  margs=$(/usr/bin/python3 -B "$here/pile_record.py" mapargs "$dir") || { r=$?; cleanup; tmp=""; return $r; }
  mapfile -t cgargs <<< "$margs"
  "$ekmcompare" cg "${cgargs[@]}" --quiet -o "$tmp/cg.h5" "$dir/atoms.dump" || { r=$?; cleanup; tmp=""; return $r; }
  /usr/bin/python3 -B "$here/pile_record.py" make "${force[@]+"${force[@]}"}" --law "$law" --member "$k" \
    --from "$tmp" -o "$rec" "$dir" || { r=$?; cleanup; tmp=""; return $r; }
  tmp=""
  echo "$prog: $dir -> $rec"
}

worst=0
for dir in "$@"; do
  record_run "$dir"; r=$?
  [ $r -eq 0 ] || [ $worst -ne 0 ] || worst=$r
done
exit $worst
