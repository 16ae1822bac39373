#!/usr/bin/env bash
# stale_temps.sh: remove the temporaries the campaign's steps leave when
# they are killed (ekmcompare's and the steps' OUTPUT.tmp.PID, ekm's
# OUTPUT.tmp), and say so.
#   stale_temps.sh sweep DIR...      every *.tmp.PID under DIR (4 levels:
#                                    RES/CASE/TAG/file, RES/calibration/SET/file)
#                                    whose process PID is gone
#   stale_temps.sh before OUTPUT...  every OUTPUT.tmp and OUTPUT.tmp.* (a step
#                                    about to make OUTPUT: Snakemake runs one
#                                    job per output, so any is left over)
# One line per file removed ("campaign: removed stale temporary FILE
# (why)"). A PID that is alive (also another user's) is kept. Exit status
# (docs/exit-codes.md): 0 done, 1 usage, 3 a stale temporary cannot be
# removed.
set -uo pipefail
[ $# -ge 1 ] || { echo "stale_temps.sh: usage: stale_temps.sh sweep DIR... | before OUTPUT..." >&2; exit 1; }
mode=$1; shift
rc=0
remove() { # remove FILE WHY
  if rm -f -- "$1"; then echo "campaign: removed stale temporary $1 ($2)" >&2
  else echo "campaign: $1: cannot remove the stale temporary" >&2; rc=3; fi
}
alive() { kill -0 "$1" 2> /dev/null || [ -d "/proc/$1" ]; }
case $mode in
  sweep)
    for d; do
      [ -d "$d" ] || continue
      while IFS= read -r -d '' f; do
        pid=${f##*.tmp.}
        alive "$pid" || remove "$f" "process $pid is gone"
      done < <(find "$d" -maxdepth 4 -type f -regex '.*\.tmp\.[0-9]+' -print0)
    done ;;
  before)
    for o; do
      for f in "$o".tmp "$o".tmp.*; do
        [ -e "$f" ] || [ -L "$f" ] || continue
        remove "$f" "left by an interrupted step making ${o##*/}"
      done
    done ;;
  *) echo "stale_temps.sh: unknown mode '$mode' (sweep, before)" >&2; exit 1 ;;
esac
exit $rc
