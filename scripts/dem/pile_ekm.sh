#!/usr/bin/env bash
# scripts/dem/pile_ekm.sh: the 2D EKM sand piles in the DEM's geometry
# (issue 34, item 4; docs/dem.md "The EKM pile in the DEM's geometry"):
# one `ekm run scenarios/sandpile.ini` per point of the DEM's sweep (the
# hopper and the sieve) and model variant, each with the point's ekm_set
# (`ekm scenario scenarios/sandpile.ini --engine ENGINE --size SIZE
# --json`: its source's width and mass flux, its pouring time, the plate,
# the end time), then figures/pile2d.py on each at the end of the pouring
# and at the end (the DEM's pile at rest) into OUT/<point>_<variant>_at_<t>s/,
# and OUT/summary.md: their numbers beside the DEM's plain piles of the
# same size (OUT/../summary-plain-SIZE.json, scripts/dem/pile_analysis.sh),
# and each pile at the end scored against the DEM's mean maps of its
# source (`ekmcompare score2d`, OUT/../maps-SIZE.h5: every engine and law
# that has one) into its folder's score2d-ENGINE-LAW.json, with the engine
# floor (LAMMPS's map against LIGGGHTS's, OUT/engine_floor_LAW_SOURCE/)
# where both engines have a map; OUT/pile_base.pdf, .png, .csv: the base
# pressure p(x) of the DEM's plain piles (mean +- 2 SE over the runs of
# OUT/../base-plain-ENGINE-SOURCE-SIZE.h5) beside every EKM pile in RUNS at
# the end (figures/pile_base.py); OUT/maps_SOURCE.pdf, .png: phi and
# sigma_zz of the DEM's plain mean maps beside every EKM pile at the end
# (figures/pilemaps.py).
#
#   scripts/dem/pile_ekm.sh [-e ENGINE] [-s SIZE] [-v "VARIANTS"] [-m "NAME=FIT.ini ..."] [-o OUT] [BUILD_DIR]
#
# ENGINE lammps (default) or liggghts: the keys it resolves (the ekm_set is
# the same for both today); SIZE ref (default) or smoke; VARIANTS default
# "thesis full"; -m: material sets (`ekm run --material FIT.ini`, e.g.
# rheology=results/calibration/rheology/fit.ini), each run of a set named
# <point>_<size>_<variant>_<NAME> (without -m: the scenario's own
# [material], no suffix); OUT default results/sandpile/ekm. Runs go to RUNS (default
# runs/pile_ekm/, not committed), resumable as scripts/thesis2d.sh's
# (scripts/lib/ekm_runs.sh), JOBS at a time (default 1: the DEM ensemble
# usually holds the other core). About 500 s each on one core (ref, 65 x
# 20 cells, 2026-12-07).
# Exit status: 0; 1 usage or a missing program; 2 a run, a figure or a score failed.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
prog=pile_ekm.sh
engine=lammps size=ref variants="thesis full" sets="" out=$root/results/sandpile/ekm
while getopts ":e:s:v:m:o:h" o; do
  case $o in
    e) engine=$OPTARG ;;
    s) size=$OPTARG ;;
    v) variants=$OPTARG ;;
    m) sets=$OPTARG ;;
    o) out=$OPTARG ;;
    h) sed -n '2,36p' "$0"; exit 0 ;;
    :) echo "$prog: -$OPTARG needs a value (see -h)" >&2; exit 1 ;;
    *) echo "$prog: -$OPTARG: unknown option (see -h)" >&2; exit 1 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -le 1 ] || { echo "$prog: usage: pile_ekm.sh [-e ENGINE] [-s SIZE] [-v VARIANTS] [-m SETS] [-o OUT] [BUILD_DIR]" >&2; exit 1; }
# the material sets: "suffix --material FILE" per line ("" and none: the scenario's)
materials=""
for m in $sets; do
  mname=${m%%=*} mfile=${m#*=}
  if [ -z "$mname" ] || [ "$mname" = "$m" ] || [[ $mname == */* ]] || [ ! -f "$mfile" ]; then
    echo "$prog: -m $m: expected NAME=FIT.ini (NAME without / or blanks) with an existing file" >&2
    exit 1
  fi
  materials+="_$mname $mfile"$'\n'
done
[ -n "$materials" ] || materials=$' -'$'\n'
build=${1:-build}
case $build in
  /*) ekm=$build/continuum/ekm ;;
  *) ekm=$root/$build/continuum/ekm ;;
esac
[ -x "$ekm" ] || { echo "$prog: $ekm not built (make build)" >&2; exit 1; }
runs=${RUNS:-$root/runs/pile_ekm}
jobs=${JOBS:-1}
py=/usr/bin/python3
mkdir -p "$runs" "$out"

# the points: "tag t_stop t_end set set ..." per line (a single point, tag
# "", is "pile")
resolved=$("$ekm" scenario "$root/scenarios/sandpile.ini" --engine "$engine" --size "$size" --json) ||
  exit 1
points=$($py -c '
import json, sys
for p in json.load(sys.stdin)["points"]:
    sets = dict(s.split("=", 1) for s in p["ekm_set"])
    for k in ("top.t_stop", "run.t_end"):
        if k not in sets:
            sys.exit("pile_ekm.sh: point %r: no %s in its ekm_set" % (p["tag"], k))
    src = "sieve" if float(sets.get("top.inlet_width", 0)) >= float(sets.get("bottom.plate_width", 1e300)) else "hopper"
    print(p["tag"] or "pile", src, sets["top.t_stop"], sets["run.t_end"], " ".join(p["ekm_set"]))' <<< "$resolved") ||
  exit 1
cases=()
while read -r tag _ t_stop t_end point_sets; do
  args=""
  for s in $point_sets; do args+=" --set $s"; done
  for v in $variants; do
    while read -r suffix mfile; do
      [ -n "$suffix" ] || continue
      if [ "$suffix" = - ]; then suffix="" mopt=""; else mopt=" --material $mfile"; fi
      cases+=("${tag}_${size}_$v$suffix sandpile$args --set model.variant=$v$mopt")
    done <<< "$materials"
  done
done <<< "$points"

# shellcheck source=scripts/lib/ekm_runs.sh
. "$root/scripts/lib/ekm_runs.sh"
fail=0
ekm_runs pile_ekm || fail=2

# the DEM's mean maps (scripts/dem/pile_analysis.sh): their groups
# /ENGINE/LAW/SOURCE
maps=$(dirname "$out")/maps-$size.h5
groups=""
if [ -f "$maps" ]; then
  groups=$($py -c '
import sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    f.visit(lambda n: print("/" + n, end=" ") if n.count("/") == 2 and "phi" in f[n] else None)' "$maps") ||
    { echo "$prog: $maps: cannot list its map groups" >&2; exit 2; }
fi
compare=$(dirname "$(dirname "$ekm")")/compare/ekmcompare
# score2d ARGS... OUT.json: ekmcompare score2d, its table to the log
score2d() {
  local o=${*: -1}
  "$compare" score2d "${@:1:$#-1}" -o "$o" >&2 || fail=2
}

base_args=()
while read -r tag src t_stop t_end _; do
  # the base-pressure figure: the DEM's plain groups of this source and
  # every EKM run of the point in RUNS (all variants and sets made so far)
  for e in lammps liggghts; do
    f=$(dirname "$out")/base-plain-$e-$src-$size.h5
    [ -f "$f" ] && base_args+=(--dem "$src:$e=$f")
  done
  # every EKM run of the point, for both figures (pile_base, pilemaps)
  map_args=()
  for f in "$runs/${tag}_${size}"_*.h5; do
    [ -f "$f" ] || continue
    lab=$(basename "$f" .h5) lab=${lab#"${tag}_${size}_"}
    base_args+=(--ekm "$src:$lab=$f")
    map_args+=(--ekm "$lab=$f")
  done
  base_time=$t_end
  for c in "${cases[@]}"; do
    name=${c%% *}
    case $name in "${tag}"_*) ;; *) continue ;; esac
    [ -f "$runs/$name.h5" ] || continue
    for t in $(printf '%.2f\n' "$t_stop") "$t_end"; do
      $py -B "$root/figures/pile2d.py" "$runs/$name.h5" "$out/${name}_at_${t}s" \
        --times 0.5,1,2,"$t_end" --base-time "$t" >&2 || fail=2
    done
    # the pile at rest against each DEM map of its source
    for g in $groups; do
      case $g in */"$src") ;; *) continue ;; esac
      e=${g#/} e=${e%%/*} l=${g#/*/} l=${l%/*}
      score2d --dem "$maps" --group "$g" --model "$runs/$name.h5" --time "$t_end" \
        "$out/${name}_at_${t_end}s/score2d-$e-$l.json"
    done
  done
  # the maps at rest: each engine's plain mean map beside every EKM run of
  # the point at the end (figures/pilemaps.py; OUT/maps_SOURCE.pdf, .png)
  dem_maps=()
  for e in lammps liggghts; do
    case " $groups " in *" /$e/plain/$src "*) dem_maps+=(--map "$e=$maps:/$e/plain/$src") ;; esac
  done
  map_args=("${dem_maps[@]}" "${map_args[@]}")
  if [ ${#map_args[@]} -gt 0 ]; then
    $py -B "$root/figures/pilemaps.py" "$out/maps_$src" "${map_args[@]}" --time "$t_end" \
      --title "$src: the DEM's plain mean maps at rest ($(basename "$maps")) and the EKM at $t_end s" >&2 || fail=2
  fi
  # the engine floor: one engine's map against the other's
  for g in $groups; do
    case $g in /lammps/*/"$src") ;; *) continue ;; esac
    l=${g#/*/} l=${l%/*}
    case " $groups " in *" /liggghts/$l/$src "*) ;; *) continue ;; esac
    mkdir -p "$out/engine_floor_${l}_$src"
    score2d --dem "$maps" --group "/liggghts/$l/$src" --model "$maps" --model-group "$g" \
      "$out/engine_floor_${l}_$src/score2d-lammps-$l.json"
  done
done <<< "$points"

# p(x) under the piles at rest: the DEM's ensembles with +-2 SE bands
# beside every EKM pile (figures/pile_base.py; OUT/pile_base.pdf, .png and
# the curves as .csv)
if [ ${#base_args[@]} -gt 0 ]; then
  $py -B "$root/figures/pile_base.py" "$out/pile_base" "${base_args[@]}" --time "$base_time" >&2 || fail=2
fi

# the table: every EKM folder's numbers (pile2d.json) and the DEM groups'
dem=$(dirname "$out")/summary-plain-$size.json
dem_opt=()
[ -f "$dem" ] && dem_opt=(--dem "$dem")
$py -B "$root/figures/pile2d_table.py" "$out" "$out/summary.md" "${dem_opt[@]}" \
  --title "The EKM sand piles in the DEM's geometry ($size size)" \
  --about "Written by scripts/dem/pile_ekm.sh from each folder's pile2d.json (figures/pile2d.py: the definitions; the EKM's base pressure is P of its bottom row of cells, 2 d wide) and, for the DEM, from $(basename "$dem") beside OUT (scripts/dem/pile_analysis.sh: the records' mean +- SE over seeds; p(centre)/p(max) of the floor's normal stress in 4 d bins)." ||
  fail=2
exit "$fail"
