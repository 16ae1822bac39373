#!/usr/bin/env bash
# table.sh: the campaign's score table from the per-point score files
# (rule table of workflow/Snakefile).
#   table.sh SIZE RES "ENGINES" PLAN.json
# PLAN.json (written by the Snakefile from the resolved scenarios): one
# object per campaign scenario, {"scenario", "engines": [the engines that
# can run it, of ENGINES], "fields": "phi,vx,...", "points": [{"tag",
# "vars"}]} (vars: the point's sweep variables from the resolved scenario,
# `points[].vars` of docs/resolved-scenario.md; each row carries them, so
# that the figures read a point's phi and rate from the table).
# Writes RES/scores.json and RES/scores.md (atomically) and prints the
# markdown table. One row per scenario x sweep point x scored field, with
# the relative L2 error and the noise-normalised error (docs/model-notes.md section 9)
# of EKM vs LIGGGHTS, EKM vs LAMMPS and LIGGGHTS vs LAMMPS (the floor).
# A comparison that cannot exist (engine cannot run the scenario, or not in
# ENGINES) is "n/a"; one whose score file is missing (failed step) is
# "missing" (with a warning; the campaign's exit status reports the failed
# step itself), and so is one whose score records inputs (score_step.sh:
# path and sha256 of its cg and EKM files) that are gone or changed since
# ("reason": "input gone" / "input changed"; "missing (input changed)" in
# the markdown), never the old numbers; a score without that record (made
# before scores recorded their inputs) is shown with "inputs":
# "unrecorded" ("[inputs unrecorded]"); one whose EKM run was to stop when steady and ended at its
# t_end without getting there ("model_run" of the score, steady 0) is
# "not_steady" with its flow-rate acceleration, not scored as a steady state
# (the score file keeps the numbers of that transient; the matrix leaves it
# out); the scalar cells likewise.
# Exit status (docs/exit-codes.md): 1 usage, 2 bad plan,
# 3 the table cannot be written, 7 no jq.
set -uo pipefail
prog=table.sh
root=$(cd "$(dirname "$0")/../.." && pwd)
die() { echo "$prog: $1" >&2; exit "${2:-1}"; }
[ $# -eq 4 ] || die "usage: table.sh SIZE RES \"ENGINES\" PLAN.json"
size=$1 res=$2 engines=$3 plan=$4
# absolute, as the script works from the checkout's top folder
case $res in /*) ;; *) res=$PWD/$res ;; esac
case $plan in /*) ;; *) plan=$PWD/$plan ;; esac
command -v jq > /dev/null || die "jq not installed (scripts/deps.sh)" 7
jq -e 'type == "array"' "$plan" > /dev/null 2>&1 || die "$plan: expected a JSON array (the campaign plan)" 2
cd "$root" || exit 3
# code version as in the tools' outputs (cmake/version.cmake): -dirty when
# tracked sources other than results/ differ from the commit
version() {
  local v; v=$(git describe --always --abbrev=12 2>/dev/null) || { echo unknown; return; }
  [ -n "$(git status --porcelain --untracked-files=no -- . ':(exclude)results' 2>/dev/null)" ] && v=$v-dirty
  echo "$v"
}
rows=$(mktemp); trap 'rm -f "$rows" "$res/scores.json.tmp" "$res/scores.md.tmp"' EXIT
# the score files as the table names them: relative to the checkout
# when inside it (as the scores name their inputs)
relpath() { case $1 in "$root"/*) echo "${1#"$root"/}" ;; *) echo "$1" ;; esac; }
# The inputs each score records (score_step.sh: "inputs", the path and
# sha256 of its cg and EKM files), checked once each: SUMS = {path: sha256}
# of those that exist. A score whose input is gone or changed is a missing
# comparison with the reason ("input gone", "input changed"), not its old
# numbers; one without a record (made before scores recorded their
# inputs) is shown, marked "inputs unrecorded".
sums_list=$(mktemp); trap 'rm -f "$rows" "$sums_list" "$res/scores.json.tmp" "$res/scores.md.tmp"' EXIT
while IFS= read -r -d '' f; do
  jq -r '.inputs // {} | .[] | .path // empty' "$f" 2> /dev/null || :
done < <(find "$res" -type f -name 'score_*.json' -print0 2> /dev/null) | sort -u |
  while IFS= read -r p; do if [ -f "$p" ]; then printf '%s\0' "$p"; fi; done |
  xargs -0 -r sha256sum -- > "$sums_list" || die "cannot compute the checksums of the scores' inputs" 3
SUMS=$(jq -Rn '[inputs | capture("^(?<s>[0-9a-f]{64}) [ *](?<p>.*)$") | {(.p): .s}] | add // {}' "$sums_list") ||
  die "cannot read the checksums of the scores' inputs" 5
rm -f "$sums_list"
# jq: instate: "ok", "unrecorded", "input gone" or "input changed" for the
# score read
INSTATE='def instate: if .inputs == null then "unrecorded"
  else [.inputs[] | if $sums[.path] == null then "input gone" elif $sums[.path] != .sha256 then "input changed" else empty end]
       | if length == 0 then "ok" elif index("input gone") != null then "input gone" else "input changed" end end;'
# cell FILE FIELD USABLE: JSON for one comparison
cell() {
  if [ "$3" != 1 ]; then echo '{"status": "n/a"}'
  elif [ ! -f "$1" ]; then echo "{\"status\": \"missing\", \"file\": \"$(relpath "$1")\"}"
  else jq -c --arg f "$2" --arg file "$(relpath "$1")" --argjson sums "$SUMS" "$INSTATE"'
      instate as $in | .fields[$f] as $r | if $in == "input gone" or $in == "input changed" then
         {status: "missing", reason: $in, inputs: [.inputs[].path], file: $file}
       elif $r == null then {status: "missing", file: $file}
       elif $r.n_a then {status: "n/a", reason: $r.n_a, file: $file}
       elif .model_run.steady == 0 then {status: "not_steady", acceleration: .model_run.acceleration,
             drift_per_s: .model_run.drift_per_s, file: $file}
       else {status: "ok", rel_l2: $r.rel_l2, noise_normalised: $r.noise_normalised, points: $r.points,
             points_left_out: $r.points_left_out, offset_d: .free_surface.offset_d, offset_m: .free_surface.offset_m,
             file: $file} end | if $in == "unrecorded" and .status != "missing" then . + {inputs: "unrecorded"} else . end' "$1"
  fi
}
# scell FILE USABLE: the scalars of one comparison, {name: {...}}
scell() {
  if [ "$2" != 1 ] || [ ! -f "$1" ]; then echo '{}'
  else jq -c --arg file "$(relpath "$1")" --argjson sums "$SUMS" "$INSTATE"'instate as $in
      | if $in == "input gone" or $in == "input changed" then [.inputs[].path] as $i | (.scalars // {}) | map_values({status: "missing", reason: $in, inputs: $i, file: $file})
      elif .model_run.steady == 0 then (.scalars // {}) | map_values({status: "not_steady", file: $file})
      else (.scalars // {}) | map_values(. + {file: $file}) end
      | if $in == "unrecorded" then map_values(. + {inputs: "unrecorded"}) else . end' "$1"
  fi
}
# sxcell FILE USABLE: as scell, and {"__status": "missing"} when the file is
# missing (a fitted parameter set's scalar cells)
sxcell() {
  if [ "$2" = 1 ] && [ ! -f "$1" ]; then echo '{"__status": "missing"}'; else scell "$@"; fi
}
# set_cells CELLFUN [FIELD]: the fitted parameter sets' cells of one row,
# {"ekm_<set>_vs_<engine>": CELLFUN's JSON} (of the loop below: $psets, $d,
# $ok_l, $ok_m)
set_cells() {
  local fun=$1 x='{}' p; shift
  for p in $psets; do
    x=$(jq -cn --argjson x "$x" --arg p "$p" \
      --argjson a "$("$fun" "$d/score_ekm_${p}_liggghts.json" "$@" $ok_l)" \
      --argjson b "$("$fun" "$d/score_ekm_${p}_lammps.json" "$@" $ok_m)" \
      '$x + {("ekm_" + $p + "_vs_liggghts"): $a, ("ekm_" + $p + "_vs_lammps"): $b}')
  done
  echo "$x"
}
srows=$(mktemp); trap 'rm -f "$rows" "$sums_list" "$srows" "$res/scores.json.tmp" "$res/scores.md.tmp"' EXIT
# one line per scenario x point; tag "-" for the single case
while IFS=$'\t' read -r s sup fields tag pvars psets; do
  ok_l=0 ok_m=0
  case " $sup " in *" liggghts "*) ok_l=1 ;; esac
  case " $sup " in *" lammps "*) ok_m=1 ;; esac
  both=$(( ok_l & ok_m ))
  [ "$tag" = - ] && tag=
  d=$res/$s${tag:+/$tag}
  for f in ${fields//,/ }; do
    extra=$(set_cells cell "$f")
    jq -cn --arg s "$s" --arg p "$tag" --arg f "$f" --argjson v "$pvars" --argjson x "$extra" \
      --argjson a "$(cell "$d/score_ekm_liggghts.json" "$f" $ok_l)" \
      --argjson b "$(cell "$d/score_ekm_lammps.json" "$f" $ok_m)" \
      --argjson c "$(cell "$d/score_liggghts_lammps.json" "$f" $both)" \
      '{scenario: $s, point: $p, vars: $v, field: $f, ekm_vs_liggghts: $a, ekm_vs_lammps: $b, liggghts_vs_lammps: $c} + $x' >> "$rows"
  done
  # the scalars (scalars of the score files; the names of the first that has them)
  extra=$(set_cells sxcell)
  jq -cn --arg s "$s" --arg p "$tag" --argjson x "$extra" \
    --argjson a "$(scell "$d/score_ekm_liggghts.json" $ok_l)" \
    --argjson b "$(scell "$d/score_ekm_lammps.json" $ok_m)" \
    --argjson c "$(scell "$d/score_liggghts_lammps.json" $both)" \
    '[$b, $a, $c, ($x | .[] | del(.__status))] as $all | ([$all[] | keys_unsorted] | map(select(length > 0)) | .[0] // [])[] as $k
     | {scenario: $s, point: $p, scalar: $k, units: ([$all[][$k].units // empty][0]),
        ekm_vs_liggghts: ($a[$k] // {status: "n/a"}), ekm_vs_lammps: ($b[$k] // {status: "n/a"}),
        liggghts_vs_lammps: ($c[$k] // {status: "n/a"})}
       + ($x | map_values(.[$k] // {status: (if .__status then .__status elif length > 0 then "missing" else "n/a" end)}))' >> "$srows"
done < <(jq -r '.[] | . as $sc | .points[] | [$sc.scenario, ($sc.engines | join(" ")), $sc.fields,
                       (if .tag == "" then "-" else .tag end), (.vars | tojson), (($sc.sets // []) | join(" "))] | @tsv' "$plan")
allsets=$(jq -r '[.[].sets // [] | .[]] | unique | join(" ")' "$plan")
missing=0
grep -q '"status":"missing"' "$rows" && missing=1
mkdir -p "$res" || die "$res: cannot create the results folder" 3
jq -s --arg size "$size" --arg engines "$engines" --arg created "$(date -u +%Y-%m-%dT%H:%M:%SZ)" \
  --arg version "$(version)" \
  --slurpfile scalars "$srows" \
  '{size: $size, engines: ($engines | split(" ")), created: $created, code_version: $version,
    definitions: {rel_l2: "||f_model - f_DEM|| / ||f_DEM|| over the points both cover (docs/model-notes.md section 9)",
                  noise_normalised: "sqrt(mean(((f_model - f_DEM) / SE)^2)); 1 = as close as the DEM noise; SE of both engines in quadrature for engine vs engine",
                  points_left_out: "DEM points with material not compared: off the common support (phi <= support x the DEM maximum on either side), or outside the model grid",
                  offset_d: "free-surface offset, model layer height - DEM layer height (phi crossing half its maximum), in mean grain diameters",
                  rel_error: "scalar: (model - DEM) / |DEM|",
                  error_over_se: "scalar: (model - DEM) / SE, SE = the DEM SE (and the model SE in quadrature for engine vs engine)"},
    rows: ., scalar_rows: $scalars}' "$rows" > "$res/scores.json.tmp" || die "$res/scores.json.tmp: cannot write the score table" 3
{
  echo "# Campaign scores ($size size)"
  echo
  echo "Each cell: relative L2 error / noise-normalised error (1 = as close as the"
  echo "DEM's own noise), over the common support (phi above the support threshold"
  echo "on both sides), then in brackets the points left out by it and the"
  echo "free-surface offset (model - DEM layer height, grain diameters; - when a"
  echo "side has no free surface). LIGGGHTS vs LAMMPS is the floor no model can beat."
  echo "Made $(date -u +%Y-%m-%d) by \`make campaign SIZE=$size\` ($(version))."
  echo
  echo "| scenario | point | field | EKM vs LIGGGHTS | EKM vs LAMMPS | LIGGGHTS vs LAMMPS |"
  echo "|---|---|---|---:|---:|---:|"
  jq -r 'def c: if .status == "ok" then
             "\(if .rel_l2 == null then "-" else (.rel_l2 * 1000 | round / 1000 | tostring) end) / \(if .noise_normalised == null then "-" else (.noise_normalised * 100 | round / 100 | tostring) end) (\(.points_left_out // "-") out, \(if .offset_d == null then "-" else (.offset_d * 100 | round / 100 + 0 | tostring) + " d" end))"
           elif .status == "not_steady" then "EKM not steady (flow-rate acceleration \(.acceleration) m^2/s^2 at t_end)"
           elif .reason then "\(.status) (\(.reason))"
           else .status end + (if .inputs == "unrecorded" then " [inputs unrecorded]" else "" end);
         .rows[] | "| \(.scenario) | \(if .point == "" then "-" else .point end) | \(.field) | \(.ekm_vs_liggghts | c) | \(.ekm_vs_lammps | c) | \(.liggghts_vs_lammps | c) |"' "$res/scores.json.tmp"
  if [ -n "$allsets" ]; then
    echo
    echo "## By parameter set"
    echo
    echo "The EKM with each parameter set (thesis: the scenario files' own [material];"
    echo "the others fitted by the campaign on their training set, results/calibration.md)"
    echo "against the reference engine (LAMMPS where it runs the scenario, else"
    echo "LIGGGHTS): relative L2 error / noise-normalised error on the common support;"
    echo "the floor is LIGGGHTS vs LAMMPS."
    echo
    printf '| scenario | point | field | engine | EKM thesis |'; for p in $allsets; do printf ' EKM %s |' "$p"; done; echo ' floor |'
    printf '|---|---|---|---|---:|'; for p in $allsets; do printf -- '---:|'; done; printf -- '---:|\n'
    jq -r --arg sets "$allsets" 'def c: if .status == "ok" then
             "\(if .rel_l2 == null then "-" else (.rel_l2 * 1000 | round / 1000 | tostring) end) / \(if .noise_normalised == null then "-" else (.noise_normalised * 100 | round / 100 | tostring) end)"
           elif .status == "not_steady" then "not steady"
           elif .reason then "\(.status) (\(.reason))"
           else .status end + (if .inputs == "unrecorded" then " [inputs unrecorded]" else "" end);
         .rows[] | . as $r | (if .ekm_vs_lammps.status == "n/a" then "liggghts" else "lammps" end) as $e
         | "| \(.scenario) | \(if .point == "" then "-" else .point end) | \(.field) | \($e) | \(.["ekm_vs_" + $e] | c) |"
           + ([$sets | split(" ")[] as $p | " \($r["ekm_" + $p + "_vs_" + $e] // {status: "n/a"} | c) |"] | join(""))
           + " \(.liggghts_vs_lammps | c) |"' "$res/scores.json.tmp" || exit 3
  fi
  echo
  echo "## Scalars"
  echo
  echo "Each cell: the DEM value (the first engine named) +- its SE, the model's, and"
  echo "rel. error / error over SE (docs/compare.md \"Scalar observables\")."
  echo
  echo "| scenario | point | scalar | units | EKM vs LIGGGHTS | EKM vs LAMMPS | LIGGGHTS vs LAMMPS |"
  echo "|---|---|---|---|---:|---:|---:|"
  jq -r 'def n: if . == null then "-" else (. * 1e4 | round / 1e4 + 0 | tostring) end;
         def g: if . == null then "-" elif . == 0 then "0"
                else . as $x | ($x | fabs | log10 | floor) as $e | ($x / pow(10; $e) * 1000 | round / 1000 | tostring) + "e" + ($e | tostring) end;
         def c: if .dem == null and .model == null then (.status // "-") + (if .reason then " (\(.reason))" else "" end)
                else "\(.dem | g) +- \(.dem_se | g), \(.model | g): \(.rel_error | n) / \(if .error_over_se == null then "-" else (.error_over_se * 100 | round / 100 + 0 | tostring) end)" end
                + (if .inputs == "unrecorded" then " [inputs unrecorded]" else "" end);
         .scalar_rows[] | "| \(.scenario) | \(if .point == "" then "-" else .point end) | \(.scalar) | \(.units) | \(.ekm_vs_liggghts | c) | \(.ekm_vs_lammps | c) | \(.liggghts_vs_lammps | c) |"' "$res/scores.json.tmp"
} > "$res/scores.md.tmp" || die "$res/scores.md.tmp: cannot write the score table" 3
mv "$res/scores.json.tmp" "$res/scores.json" || die "$res/scores.json: cannot rename into place" 3
mv "$res/scores.md.tmp" "$res/scores.md" || die "$res/scores.md: cannot rename into place" 3
cat "$res/scores.md"
[ $missing = 0 ] || echo "$prog: some comparisons are missing (failed steps above); the table marks them" >&2
exit 0
