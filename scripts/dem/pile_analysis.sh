#!/usr/bin/env bash
# pile_analysis.sh: the base-pressure observable of the sand-pile ensemble
# (issue 34), from the committed run records: every group's base profiles,
# then their statistics.
#
#   scripts/dem/pile_analysis.sh [-o OUT] [-m K] ROOT SIZE
#
# ROOT is the root of the run records (results/sandpile/runs, written by
# scripts/dem/pile_rounds.sh through pile_record.sh, one per run that
# finished and passed `check_run.sh --sandpile`):
# ROOT/<law>/<engine>-<SIZE>/<point>/seed<k>/ (law plain or rolling; see
# scripts/dem/pile_record.py). No dump is read, so records made on
# different machines and sessions pool. Every record of SIZE is checked
# first (`pile_record.py list`): a bad one stops the analysis with one line
# naming its file. A group is one law, engine and source (the hopper: the
# source narrower than the plate, point source8; the sieve: as wide); per
# group with at least 2 records:
#   OUT/base-<law>-<engine>-<source>-SIZE.h5 and .csv: the records' profiles
#     (each `ekmcompare base --last 1` of its run: the pile at rest, 2 d bins
#     about the box's middle, the source's centre, aligned with the floor
#     lattice) assembled by `pile_record.py group` in the layout of
#     `ekmcompare base` (p_base_runs [runs][bins] in the order of the
#     members; inputs names the records) and, when every record has its
#     surface, h_runs, floor_grains_runs, pile_mass_runs for the local weight
# and for all of them together scripts/dem/pile_stats.py --merge K
# (default 5: 10 d bins), the hopper against the sieve per law and engine,
# and the plain law against rolling resistance per source and engine:
#   OUT/stats-SIZE.json, OUT/profiles-SIZE.h5, OUT/profiles-SIZE.csv;
# with, per group whose records all have map.h5 (pile_record.sh since the
# maps), the density and stress maps: stats-SIZE.json groups.*.map (phi
# under the apex minus phi under the flanks at matched heights, its SE
# over runs and from the maps' own noise; K_apex and whether the major
# principal stress arches over the centre; scripts/dem/pile_map.py,
# docs/dem.md "The density and stress maps") and OUT/maps-SIZE.h5 (the
# mean maps, their SEs, the principal directions); a group with a record
# without map.h5 (older or recovered) gets map_missing instead;
# and scripts/dem/pile_summary.py's table of the records' summary rows per
# law (angles, heights, extents): OUT/summary-<law>-SIZE.json (`pile_record.py
# summary`). OUT defaults to results/sandpile.
# Exit status: 0 ok; 1 usage; 2 a bad record (pile_record.py's line), ROOT
# holding runs rather than records, or no group with 2 records; 3 ROOT
# missing; otherwise a failing step's own status (pile_record.py,
# pile_stats.py: docs/exit-codes.md).
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
    h) sed -n '2,43p' "$0"; exit 0 ;;
    *) usage "bad option (see -h)" ;;
  esac
done
shift $((OPTIND - 1))
[ $# -eq 2 ] || usage "usage: pile_analysis.sh [-o OUT] [-m K] ROOT SIZE"
rroot=$1; size=$2
[ -d "$rroot" ] || { echo "$prog: $rroot: no such directory (the root of the run records, results/sandpile/runs)" >&2; exit 3; }
for d in "$rroot"/*/seed*/sandpile; do
  [ -d "$d" ] || continue
  echo "$prog: $rroot: holds runs of pile_rounds.sh ($d), expected run records: record them with scripts/dem/pile_record.sh, then give their root (results/sandpile/runs)" >&2
  exit 2
done
mkdir -p "$out" || exit 3
record=("/usr/bin/python3" -B "$here/pile_record.py")

# law engine source point member dir, checked, in the order of the members
listing=$("${record[@]}" list "$rroot" "$size") || exit
groups=(); compares=()
for law in plain rolling; do
  for engine in lammps liggghts; do
    for src in hopper sieve; do
      mapfile -t list < <(awk -v l="$law" -v e="$engine" -v s="$src" '$1 == l && $2 == e && $3 == s { print $6 }' <<< "$listing")
      if [ ${#list[@]} -lt 2 ]; then
        echo "$prog: $law $engine $src: ${#list[@]} record(s), at least 2 needed: skipped" >&2; continue
      fi
      base=$out/base-$law-$engine-$src-$size
      "${record[@]}" group -o "$base.h5" --csv "$base.csv" "${list[@]}" || exit
      groups+=("$engine/$law/$src=$base.h5")
      echo "$prog: $law $engine $src: ${#list[@]} runs -> $base.h5"
    done
  done
done
[ ${#groups[@]} -gt 0 ] || { echo "$prog: $rroot: no group with 2 records of size $size" >&2; exit 2; }
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
  --h5 "$out/profiles-$size.h5" --csv "$out/profiles-$size.csv" --maps-h5 "$out/maps-$size.h5" "${compares[@]}" "${groups[@]}" || exit
for law in plain rolling; do
  mapfile -t list < <(awk -v l="$law" '$1 == l { print $6 }' <<< "$listing" | sort -V)
  [ ${#list[@]} -gt 0 ] || continue
  "${record[@]}" summary -o "$out/summary-$law-$size.json" "${list[@]}" || exit
done
