#!/usr/bin/env bash
# pile_analysis.sh: the base-pressure observable of the sand-pile ensemble
# (issue 34): `ekmcompare base` on every group's runs, then its statistics.
#
#   scripts/dem/pile_analysis.sh [-o OUT] [-m K] ROOT SIZE
#
# ROOT is the root of scripts/dem/pile_rounds.sh (runs/pile): its laws
# ROOT/<law>/seed<k>/sandpile/<engine>-<SIZE>/<point>/ (law plain or
# rolling). A group is one law, engine and source (point source8: the
# hopper; the point whose source is as wide as the plate: the sieve); its
# runs are the finished ones (run.json status ok) that pass
# `check_run.sh --sandpile`. Per group with at least 2 runs:
#   OUT/base-<law>-<engine>-<source>-SIZE.h5 and .csv: `ekmcompare base
#     --last 1` (the pile at rest) over the runs, 2 d bins about the box's
#     middle (the source's centre), aligned with the floor lattice
# and for all of them together scripts/dem/pile_stats.py --merge K
# (default 5: 10 d bins), the hopper against the sieve per law and engine,
# and the plain law against rolling resistance per source and engine:
#   OUT/stats-SIZE.json, OUT/profiles-SIZE.h5, OUT/profiles-SIZE.csv;
# and scripts/dem/pile_summary.py's table of the same runs per law (angles,
# heights, extents): OUT/summary-<law>-SIZE.json. OUT defaults to results/sandpile.
# Exit status: 0 ok; 1 usage; 2 no group with 2 runs, or a failing step's
# own status (ekmcompare base, pile_stats.py: docs/exit-codes.md).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
prog=pile_analysis.sh
usage() { echo "$prog: $*" >&2; exit 1; }
out=$root/results/sandpile; merge=5
while getopts "o:m:h" opt; do
  case $opt in
    o) out=$OPTARG ;;
    m) merge=$OPTARG ;;
    h) sed -n '2,24p' "$0"; exit 0 ;;
    *) usage "bad option (see -h)" ;;
  esac
done
shift $((OPTIND - 1))
[ $# -eq 2 ] || usage "usage: pile_analysis.sh [-o OUT] [-m K] ROOT SIZE"
proot=$1; size=$2
[ -d "$proot" ] || { echo "$prog: $proot: no such directory (the root of pile_rounds.sh)" >&2; exit 2; }
ekmcompare=${EKMCOMPARE:-$root/build/compare/ekmcompare}
[ -x "$ekmcompare" ] || { echo "$prog: ekmcompare not built: run make build (no executable $ekmcompare)" >&2; exit 7; }
mkdir -p "$out" || exit 3

groups=(); compares=(); declare -A checked=()
for law in plain rolling; do
  for engine in lammps liggghts; do
    declare -A dumps=()
    for dir in "$proot/$law"/seed*/sandpile/"$engine-$size"/*/; do
      dir=${dir%/}
      grep -qs '"status": "ok"' "$dir/run.json" || continue
      if ! "$here/check_run.sh" --sandpile "$dir" > /dev/null 2>&1; then
        echo "$prog: $dir: check_run.sh --sandpile fails: left out" >&2; continue
      fi
      sw=$(awk '$1 == "source_width" { print $3 }' "$dir/vars.txt")
      lp=$(awk '$1 == "lp" { print $3 }' "$dir/vars.txt")
      d=$(awk '$1 == "d" { print $3 }' "$dir/vars.txt")
      src=$(awk -v w="$sw" -v lp="$lp" -v d="$d" 'BEGIN { print (w * d >= lp - 1e-9 * d ? "sieve" : "hopper") }')
      dumps[$src]+="$dir/atoms.dump"$'\n'
      checked[$law]+="$dir"$'\n'
    done
    for src in hopper sieve; do
      mapfile -t list < <(printf '%s' "${dumps[$src]:-}" | sort -V)
      if [ ${#list[@]} -lt 2 ]; then
        echo "$prog: $law $engine $src: ${#list[@]} run(s), at least 2 needed: skipped" >&2; continue
      fi
      base=$out/base-$law-$engine-$src-$size
      "$ekmcompare" base --last 1 --quiet -o "$base.h5" --csv "$base.csv" "${list[@]}" || exit
      groups+=("$engine/$law/$src=$base.h5")
      echo "$prog: $law $engine $src: ${#list[@]} runs -> $base.h5"
    done
    unset dumps
  done
done
[ ${#groups[@]} -gt 0 ] || { echo "$prog: $proot: no group with 2 finished runs of size $size" >&2; exit 2; }
have() { local g; for g in "${groups[@]}"; do [ "${g%%=*}" = "$1" ] && return 0; done; return 1; }
for engine in lammps liggghts; do
  for law in plain rolling; do
    have "$engine/$law/hopper" && have "$engine/$law/sieve" && compares+=(--compare "$engine/$law/hopper,$engine/$law/sieve")
  done
  for src in hopper sieve; do
    have "$engine/rolling/$src" && have "$engine/plain/$src" && compares+=(--compare "$engine/rolling/$src,$engine/plain/$src")
  done
done
/usr/bin/python3 -B "$here/pile_stats.py" --merge "$merge" -o "$out/stats-$size.json" \
  --h5 "$out/profiles-$size.h5" --csv "$out/profiles-$size.csv" "${compares[@]}" "${groups[@]}" || exit
for law in plain rolling; do
  mapfile -t list < <(printf '%s' "${checked[$law]:-}" | sort -V)
  [ ${#list[@]} -gt 0 ] || continue
  /usr/bin/python3 -B "$here/pile_summary.py" --runs -o "$out/summary-$law-$size.json" "${list[@]}" || exit
done
