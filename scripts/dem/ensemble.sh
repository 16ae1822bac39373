#!/usr/bin/env bash
# ensemble.sh: run the seed ensemble of a DEM scenario in one engine at one size.
#
#   scripts/dem/ensemble.sh [-f] [-o DIR] [-m K] [-s key=value]... [-P TAG]... SCENARIO ENGINE SIZE
#
# The ensemble has [dem] seeds members (the <engine>.<size>. lookup of the
# resolved scenario, `ekmscenario ... --json`); member k = 1..N runs every
# sweep point of the scenario through scripts/dem/run.sh with -s seed=P_k,
# where P_1 is [dem] seed and P_k the 3(k-1)-th prime after it (the decks
# use seed and the next two primes, seed2 and seed3: every member has its
# own three), into DIR/seed<k>/<scenario>/<engine>-<size>[/<point>]/.
#
#   -o DIR  ensemble root (default runs/ensemble)
#   -m K    run member K only (1..N; e.g. two members at once on two cores)
#   -f      passed to run.sh: redo finished runs
#   -s k=v  passed to run.sh (repeatable): a [dem] override for every
#           member, e.g. -s rolling_friction=0.1 (give such a variant its
#           own -o DIR: run.sh redoes a run whose variables changed)
#   -l      list the members, one "k seed" per line, and run nothing
#   -P TAG  passed to run.sh (repeatable): only the sweep point TAG
#
# Exit status (docs/exit-codes.md): 0 all members ok; 1 usage; 2 scenario
# error (no [dem] seeds for this engine and size: the reader's or this
# line); otherwise the worst status of run.sh over the members (4 before 6).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
prog=ensemble.sh
usage() { echo "$prog: $*" >&2; exit 1; }

force=(); outroot=$root/runs/ensemble; member=""; list=0; sets=()
while getopts "flo:m:s:P:h" opt; do
  case $opt in
    f) force=(-f) ;;
    l) list=1 ;;
    o) outroot=$OPTARG ;;
    m) member=$OPTARG ;;
    s) sets+=(-s "$OPTARG") ;;
    P) sets+=(-P "$OPTARG") ;;
    h) sed -n '2,25p' "$0"; exit 0 ;;
    *) usage "bad option (see -h)" ;;
  esac
done
shift $((OPTIND - 1))
[ $# -eq 3 ] || usage "usage: ensemble.sh [-f] [-o DIR] [-m K] [-s key=value]... [-P TAG]... SCENARIO ENGINE SIZE"
scen=$1; engine=$2; size=$3
[[ $scen =~ ^[A-Za-z0-9_-]+$ ]] || usage "bad scenario name '$scen'"
ini=$root/scenarios/$scen.ini
[ -r "$ini" ] || { echo "$prog: no scenario file $ini" >&2; exit 2; }
ekmscenario=${EKMSCENARIO:-$root/build/scenario/ekmscenario}
[ -x "$ekmscenario" ] || { echo "$prog: ekmscenario not built: run make build (no executable $ekmscenario)" >&2; exit 7; }
resolved=$("$ekmscenario" "$ini" --engine "$engine" --size "$size" --json) || exit
n=$(jq -r '.keys["dem.seeds"].value // empty' <<< "$resolved")
seed=$(jq -r '.keys["dem.seed"].value // empty' <<< "$resolved")
[ -n "$n" ] || { echo "$prog: $ini: [dem] seeds: missing for engine $engine, size $size" >&2; exit 2; }
if [ -n "$member" ]; then
  [[ $member =~ ^[1-9][0-9]*$ ]] && [ "$member" -le "$n" ] || usage "-m $member: expected a member 1..$n"
fi

# the seeds P_1..P_N: every third prime from [dem] seed
seeds=$(awk -v s="$seed" -v n="$n" 'function isprime(m,  k) { if (m < 2) return 0
    for (k = 2; k * k <= m; k++) if (m % k == 0) return 0; return 1 }
  BEGIN { p = s; print p; for (k = 2; k <= n; k++) { for (j = 0; j < 3; j++) { p++; while (!isprime(p)) p++ } print p } }')
worst=0; k=0
for p in $seeds; do
  k=$((k + 1))
  [ -z "$member" ] || [ "$member" -eq "$k" ] || continue
  if [ $list -eq 1 ]; then echo "$k $p"; continue; fi
  "$here/run.sh" "${force[@]+"${force[@]}"}" "${sets[@]+"${sets[@]}"}" -o "$outroot/seed$k" -s "seed=$p" "$scen" "$engine" "$size"; r=$?
  if [ $r -ne 0 ] && { [ $worst -eq 0 ] || [ $worst -eq 6 ]; }; then worst=$r; fi
done
exit $worst
