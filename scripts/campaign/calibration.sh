#!/usr/bin/env bash
# calibration.sh: the campaign's train/test matrix (rule calibration of
# workflow/Snakefile; docs/campaign.md "Calibration").
#   calibration.sh RES PLAN.json
# PLAN.json (written by the Snakefile): {"size", "engines", "scenarios":
# [every campaign scenario], "sets": [{"name", "fit": the fit's FIT.json
# relative to RES or null (thesis), "train": [the member scenarios],
# "how": "rheology"|"scenario"|null, "closure": the closure style of a
# closure set or null, "runs": false when the solvers cannot run it,
# "skips": {scenario: why its solver does not take it}}]}.
# Reads RES/scores.json (table.sh) and every set's FIT.json; writes
# RES/calibration.json and RES/calibration.md (atomically) and prints the
# markdown. A cell (set x scenario):
#   rel_l2      mean of the relative L2 errors of phi, vx, P and T (those the
#               scenario scores) over its points, on the common support,
#               against the reference engine (LAMMPS where it runs the
#               scenario, else LIGGGHTS): the cells ekm_vs_E (thesis) or
#               ekm_<set>_vs_E of scores.json;
#   rel_l2_no_T the same over phi, vx and P only (every closure has them:
#               the like-for-like table of the closures);
#   scalar_rel  mean |relative error| of the scenario's scalar observables
#               over its points (same engine);
#   n_scores    the relative L2 errors averaged; missing: comparisons of
#               the set that have no score (a failed step); not_steady:
#               comparisons left out because the EKM run with that set
#               ended at its t_end without reaching its steady state;
#   no_solver   the set's closure has no solver yet: fitted, not run (its
#               cells say n/a);
#   not_taken   the set's closure has a slab solver that does not take this
#               scenario (mu_i's: a no-slip base under a free surface or a
#               pressure-held wall): the solver's reason, from the plan's
#               "skips" (the cell says n/a (not taken); the reasons follow
#               the table);
#   train       whether the scenario is in the set's training data.
# The floor row is LIGGGHTS vs LAMMPS (the scenarios both engines run).
# Exit status (docs/exit-codes.md): 1 usage, 2 bad plan or score table,
# 3 cannot write, 7 no jq.
set -uo pipefail
prog=calibration.sh
die() { echo "$prog: $1" >&2; exit "${2:-1}"; }
[ $# -eq 2 ] || die "usage: calibration.sh RES PLAN.json"
res=$1 plan=$2
command -v jq > /dev/null || die "jq not installed (scripts/deps.sh)" 7
jq -e '.sets | type == "array"' "$plan" > /dev/null 2>&1 || die "$plan: expected the calibration plan ({\"sets\": [...]})" 2
jq -e '.rows | type == "array"' "$res/scores.json" > /dev/null 2>&1 ||
  die "$res/scores.json: expected the campaign's score table (rows); run the table first" 2
trap 'rm -f "$res/calibration.json.tmp" "$res/calibration.md.tmp"' EXIT
# the fits, {set: FIT.json or null}
fits='{}'
while IFS=$'\t' read -r name fit; do
  if [ "$fit" = - ]; then
    fits=$(jq -cn --argjson f "$fits" --arg n "$name" '$f + {($n): null}')
  else
    [ -f "$res/$fit" ] || die "$res/$fit: missing (the fit of set $name named in $plan)" 2
    jq -e '(.params | type == "object") and (.fields | type == "array") and (.dof | type == "number")
           and (.chi2_dof | type == "number") and (.identifiable | type == "object")' "$res/$fit" > /dev/null 2>&1 ||
      die "$res/$fit: expected an ekmcompare fit output (params, fields, dof, chi2_dof, identifiable)" 2
    fits=$(jq -c --argjson f "$fits" --arg n "$name" \
      '$f + {($n): {chi2_dof, dof, params, identifiable, why_not, fields, start: .start.source,
                   inputs: ((.points // .cases) | length)}}' "$res/$fit")
  fi
done < <(jq -r '.sets[] | [.name, (.fit // "-")] | @tsv' "$plan")
jq --slurpfile plan "$plan" --argjson fits "$fits" --arg created "$(date -u +%Y-%m-%dT%H:%M:%SZ)" '
  def mean: if length == 0 then null else add / length end;
  def engine_of: if .ekm_vs_lammps.status == "n/a" then "liggghts" else "lammps" end;
  def cellname($set; $e): if $set == "thesis" then "ekm_vs_" + $e else "ekm_" + $set + "_vs_" + $e end;
  . as $t | $plan[0] as $p
  | ($t.rows | map(select(.field == "phi" or .field == "vx" or .field == "P" or .field == "T"))) as $rows
  | ($rows | map(select(.field != "T"))) as $rows_noT
  | ($t.scalar_rows // []) as $srows
  | {size: $p.size, engines: $p.engines, created: $created, code_version: $t.code_version,
     definitions: {rel_l2: "mean relative L2 error of phi, vx, P, T over the scenario'"'"'s points, common support, against the reference engine (LAMMPS where it runs the scenario, else LIGGGHTS)",
                   rel_l2_no_T: "the same over phi, vx and P only: the fields every closure has (mu_i has no T), the like-for-like comparison of the closures",
                   scalar_rel: "mean |relative error| of the scenario'"'"'s scalar observables over its points, same engine",
                   n_scores: "relative L2 errors averaged", points: "DEM points those errors were taken over (sets on the same scenario can differ: each run has its own common support)", missing: "comparisons of the set without a score (failed step)",
                   not_steady: "comparisons left out: the EKM run with the set ended at t_end without reaching its steady state",
                   no_solver: "the set'"'"'s closure has no solver yet (docs/model/closures.md): fitted, not run",
                   not_taken: "the set'"'"'s closure has a slab solver that does not take the scenario (its reason; docs/model/closures.md)",
                   train: "the scenario is in the set'"'"'s training data"},
     sets: [$p.sets[] | . + {fitted: $fits[.name]}],
     scenarios: $p.scenarios,
     matrix: ([$p.sets[] as $set | {key: $set.name, value: ([$p.scenarios[] as $s
       | ($rows | map(select(.scenario == $s) | (.[cellname($set.name; engine_of)] // {status: "missing"}))) as $cells
       | ($rows_noT | map(select(.scenario == $s) | (.[cellname($set.name; engine_of)] // {status: "missing"}))) as $cells_noT
       | ($srows | map(select(.scenario == $s)) | map(. as $r
           | ($t.rows | map(select(.scenario == $r.scenario and .point == $r.point)) | (.[0] // {}) | engine_of) as $e
           | ($r[cellname($set.name; $e)] // {}))) as $scells
       | {key: $s, value: {
           rel_l2: ($cells | map(select(.status == "ok" and .rel_l2 != null) | .rel_l2) | mean),
           rel_l2_no_T: ($cells_noT | map(select(.status == "ok" and .rel_l2 != null) | .rel_l2) | mean),
           scalar_rel: ($scells | map(select(.rel_error != null) | .rel_error | fabs) | mean),
           n_scores: ($cells | map(select(.status == "ok" and .rel_l2 != null)) | length),
           points: ($cells | map(select(.status == "ok") | .points // 0) | add // 0),
           missing: (if $set.runs == false or (($set.skips // {})[$s] != null) then 0
                     else ($cells | map(select(.status == "missing")) | length) end),
           not_steady: ($cells | map(select(.status == "not_steady")) | length),
           no_solver: ($set.runs == false),
           not_taken: (($set.skips // {})[$s] // null),
           train: (($set.train | index($s)) != null)}}] | from_entries)}] | from_entries),
     floor: ([$p.scenarios[] as $s
       | ($rows | map(select(.scenario == $s) | .liggghts_vs_lammps)) as $cells
       | ($srows | map(select(.scenario == $s) | .liggghts_vs_lammps)) as $scells
       | {key: $s, value: {
           rel_l2: ($cells | map(select(.status == "ok" and .rel_l2 != null) | .rel_l2) | mean),
           scalar_rel: ($scells | map(select(.rel_error != null) | .rel_error | fabs) | mean),
           n_scores: ($cells | map(select(.status == "ok" and .rel_l2 != null)) | length)}}] | from_entries)}
' "$res/scores.json" > "$res/calibration.json.tmp" || die "$res/calibration.json.tmp: cannot write the matrix" 3
{
  echo "# Calibration: train/test matrix ($(jq -r .size "$plan") size)"
  echo
  echo "Rows: the parameter set the EKM ran with (thesis: each scenario file's own"
  echo "[material], the thesis's constants with the grains' rho_p and eps0 set from"
  echo "the DEM chute's phi at 24 degrees, hence trained on the chute; the others"
  echo "fitted by \`make campaign\` on their training set)."
  echo "Columns: every campaign scenario. Each cell: mean relative L2 error of"
  echo "phi, vx, P, T (those the scenario scores) over its points on the common"
  echo "support / mean |relative error| of its scalar observables, against LAMMPS"
  echo "(LIGGGHTS where LAMMPS cannot run it); **bold**: the scenario is in the"
  echo "set's training data (in-sample). The floor is LIGGGHTS vs LAMMPS."
  echo "Made $(date -u +%Y-%m-%d) by \`make campaign SIZE=$(jq -r .size "$plan")\` ($(jq -r .code_version "$res/calibration.json.tmp"))."
  echo
  jq -r 'def n: if . == null then "-" else (. * 1000 | round / 1000 | tostring) end;
         def c: if .no_solver then "n/a (no solver)" elif .not_taken then "n/a (not taken)" elif .rel_l2 == null and .scalar_rel == null then "-" else "\(.rel_l2 | n) / \(.scalar_rel | n)" end;
         . as $c
         | "| set | " + ($c.scenarios | join(" | ")) + " |",
           "|---|" + ($c.scenarios | map("---:") | join("|")) + "|",
           ($c.sets[] as $s | "| " + $s.name + " | "
              + ([$c.scenarios[] as $x | $c.matrix[$s.name][$x] | if .train then "**" + c + "**" else c end
                  + (if .missing > 0 then " (\(.missing) missing)" else "" end)
                  + (if .not_steady > 0 then " (\(.not_steady) not steady)" else "" end)] | join(" | ")) + " |"),
           "| floor (LIGGGHTS vs LAMMPS) | " + ([$c.scenarios[] as $x | $c.floor[$x] | c] | join(" | ")) + " |"' \
    "$res/calibration.json.tmp"
  echo
  echo "Like for like: the same cells over phi, vx and P only, the fields every"
  echo "closure has (mu_i has no granular temperature, so its cells above leave T"
  echo "out while the EKM's include it)."
  echo
  jq -r 'def n: if . == null then "-" else (. * 1000 | round / 1000 | tostring) end;
         def c: if .no_solver then "n/a (no solver)" elif .not_taken then "n/a (not taken)" elif .rel_l2_no_T == null then "-" else (.rel_l2_no_T | n) end;
         . as $c
         | "| set | " + ($c.scenarios | join(" | ")) + " |",
           "|---|" + ($c.scenarios | map("---:") | join("|")) + "|",
           ($c.sets[] as $s | "| " + $s.name + " | "
              + ([$c.scenarios[] as $x | $c.matrix[$s.name][$x] | if .train then "**" + c + "**" else c end
                  + (if .not_steady > 0 then " (\(.not_steady) not steady)" else "" end)] | join(" | ")) + " |")' \
    "$res/calibration.json.tmp"
  jq -r '[.sets[] as $s | .matrix[$s.name] | to_entries[] | select(.value.not_taken) | "- \($s.name), \(.key): \(.value.not_taken)"]
         | if length > 0 then "", "n/a (not taken): the closure'"'"'s slab solver does not take the scenario:", "", .[] else empty end' \
    "$res/calibration.json.tmp"
  echo
  echo "## Fitted parameters"
  echo
  echo "Value +- SE (scaled by max(1, chi2/dof)); held: not identifiable on the"
  echo "training data (kept at the start value, the reason given); docs/compare.md"
  echo "\"ekmcompare fit\"."
  echo
  jq -r 'def g: if . == null then "-" elif . == 0 then "0"
                else . as $x | ($x | fabs | log10 | floor) as $e | ($x / pow(10; $e) * 1000 | round / 1000 | tostring) + "e" + ($e | tostring) end;
         .sets[] | select(.fitted != null) | . as $s
         | "### \(.name) (\(.how) fit\(if .closure then " of closure " + .closure else "" end) on \(.train | join(", ")): chi2/dof = \(.fitted.chi2_dof | g), dof \(.fitted.dof), \(.fitted.inputs) inputs, fields \(.fitted.fields | join(",")))",
           "",
           "| parameter | value | SE | |",
           "|---|---:|---:|---|",
           (.fitted.params | to_entries[] | "| \(.key) | \(.value.value | g) | \(.value.se | g) | \(if $s.fitted.identifiable[.key] then "fitted" else "held: " + ($s.fitted.why_not[.key] // "not identifiable") end) |"),
           ""' "$res/calibration.json.tmp"
} > "$res/calibration.md.tmp" || die "$res/calibration.md.tmp: cannot write the matrix" 3
mv "$res/calibration.json.tmp" "$res/calibration.json" || die "$res/calibration.json: cannot rename into place" 3
mv "$res/calibration.md.tmp" "$res/calibration.md" || die "$res/calibration.md: cannot rename into place" 3
cat "$res/calibration.md"
