#!/usr/bin/env bash
# pile_rounds.sh: the sand-pile reference ensemble (issue 34), member by
# member over every group, so that a run stopped at any point leaves
# groups of nearly equal size.
#
#   scripts/dem/pile_rounds.sh [-o DIR] [-R RECORDS] [-r MU_R] [-M MASS] [-e "ENGINES"] [-l "LAWS"] [-t S] SIZE [FIRST [LAST]]
#
# Member k (FIRST..LAST, default 1..[dem] seeds) of every group: for each
# engine (default "lammps liggghts"), the plain contact law into
# DIR/plain and rolling resistance (-s rolling_friction=MU_R, default 0.1,
# and with -M also -s pile_mass=MASS: a steeper pile needs more mass to
# fill the plate) into DIR/rolling (-l: the laws, default "plain rolling"), each through
# scripts/dem/ensemble.sh -m k (both sources, the hopper and the sieve).
# DIR defaults to runs/pile. A finished run is
# kept (run.sh's "is done"), so the same command resumes where it stopped.
# After each member of a group, every run of it that finished and passes
# `check_run.sh --sandpile` gets its committed record,
# RECORDS/<law>/<engine>-<SIZE>/<point>/seed<k>/ (RECORDS default
# results/sandpile/runs; scripts/dem/pile_record.sh: its base profile,
# summary row, surface, run.json and vars.txt, about 15 kB): runs/pile is
# not committed and goes with the machine, the records are what
# scripts/dem/pile_analysis.sh reads. Only the points (`run.sh -l`) of a
# member without a record are run (ensemble.sh -P), on any machine: commit
# the records and the ensemble grows from where it stood.
# One DEM process at a time; run it in the background, e.g.
#   nohup nice -n 19 scripts/dem/pile_rounds.sh ref > runs/pile.log 2>&1 &
# -t S: each run's wall-time limit (run.sh's [dem] timeout, -s timeout=S;
# default the scenario's 3600 s): on a loaded machine a run at nice 19
# needs more wall time than its CPU time.
# Exit status: 0 every run ok and recorded; 1 usage; otherwise the worst
# status of ensemble.sh and pile_record.sh (a run failing its check:
# check_run.sh's; docs/exit-codes.md), after trying every run.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
prog=pile_rounds.sh
usage() { echo "$prog: $*" >&2; exit 1; }

out=$root/runs/pile; records=$root/results/sandpile/runs; mur=0.1; rmass=""; engines="lammps liggghts"; laws="plain rolling"
tlimit=()
while getopts "o:R:r:M:e:l:t:h" opt; do
  case $opt in
    o) out=$OPTARG ;;
    R) records=$OPTARG ;;
    r) mur=$OPTARG ;;
    M) rmass=$OPTARG ;;
    e) engines=$OPTARG ;;
    l) laws=$OPTARG ;;
    t) [[ $OPTARG =~ ^[1-9][0-9]*$ ]] || usage "-t $OPTARG: expected a wall time in whole seconds"
       tlimit=(-s "timeout=$OPTARG") ;;
    h) sed -n '2,32p' "$0"; exit 0 ;;
    *) usage "bad option (see -h)" ;;
  esac
done
shift $((OPTIND - 1))
if [ $# -lt 1 ] || [ $# -gt 3 ]; then
  usage "usage: pile_rounds.sh [-o DIR] [-R RECORDS] [-r MU_R] [-M MASS] [-e ENGINES] [-l LAWS] [-t S] SIZE [FIRST [LAST]]"
fi
size=$1
ekmscenario=${EKMSCENARIO:-$root/build/scenario/ekmscenario}
[ -x "$ekmscenario" ] || { echo "$prog: ekmscenario not built: run make build (no executable $ekmscenario)" >&2; exit 7; }
n=$("$ekmscenario" "$root/scenarios/sandpile.ini" --engine lammps --size "$size" --json |
    jq -r '.keys["dem.seeds"].value // empty') || exit
[ -n "$n" ] || { echo "$prog: scenarios/sandpile.ini: [dem] seeds: missing for size $size" >&2; exit 2; }
first=${2:-1}; last=${3:-$n}
if ! [[ $first =~ ^[1-9][0-9]*$ && $last =~ ^[1-9][0-9]*$ ]] || [ "$first" -gt "$last" ] || [ "$last" -gt "$n" ]; then
  usage "members: expected 1 <= FIRST <= LAST <= $n (the [dem] seeds of size $size), got '$first' '$last'"
fi

for variant in $laws; do
  case $variant in plain|rolling) ;; *) usage "-l: unknown law '$variant' (plain, rolling)" ;; esac
done

worst=0
note() { if [ "$1" -ne 0 ] && { [ "$worst" -eq 0 ] || [ "$worst" -eq 6 ]; }; then worst=$1; fi; }
for ((k = first; k <= last; k++)); do
  for e in $engines; do
    for variant in $laws; do
      sets=()
      if [ "$variant" = rolling ]; then
        sets+=(-s "rolling_friction=$mur")
        [ -z "$rmass" ] || sets+=(-s "pile_mass=$rmass")
      fi
      # the member's points, and which of them have no record yet
      points=$("$here/run.sh" -l "${sets[@]+"${sets[@]}"}" sandpile "$e" "$size" | cut -d'|' -f1) || { note 2; continue; }
      todo=()
      for pt in $points; do
        [ -d "$records/$variant/$e-$size/$pt/seed$k" ] || todo+=(-P "$pt")
      done
      if [ ${#todo[@]} -eq 0 ]; then
        echo "$prog: member $k, $e, $variant: recorded ($records/$variant/$e-$size/*/seed$k): skipped"; continue
      fi
      echo "$prog: member $k, $e, $variant ($(date -u +%H:%M:%S))"
      # only the points without a record (-P)
      "$here/ensemble.sh" -m "$k" -o "$out/$variant" "${sets[@]+"${sets[@]}"}" "${tlimit[@]+"${tlimit[@]}"}" \
        "${todo[@]}" sandpile "$e" "$size"
      note $?
      dirs=()
      for pt in $points; do
        d=$out/$variant/seed$k/sandpile/$e-$size/$pt
        [ -f "$d/run.json" ] && dirs+=("$d")
      done
      [ ${#dirs[@]} -eq 0 ] || { "$here/pile_record.sh" -R "$records" -l "$variant" "${dirs[@]}"; note $?; }
    done
  done
done
exit "$worst"
