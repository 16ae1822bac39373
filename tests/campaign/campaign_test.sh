#!/usr/bin/env bash
# campaign_test.sh: `make campaign SIZE=smoke` (the Snakemake workflow
# workflow/Snakefile) end to end, into a scratch results and runs folder.
#   campaign_test.sh SOURCE_DIR BUILD_DIR WORK_DIR
# Checks: exit 0; the score table has one row per scenario x sweep point x
# scored field ([compare] fields), and every comparison that can exist is
# there with finite numbers; the smoke training set is fitted and every
# point scored with it, with a train/test matrix; a figure was written; a second run does no work
# ("everything is up to date"); touching one scenario file redoes only that
# scenario (and not its DEM runs, whose inputs did not change); a failing
# DEM engine is reported with its log while the other steps go on.
set -u
src=$1 build=$2 work=$3
command -v lmp > /dev/null && command -v liggghts > /dev/null || { echo "DEM engines not installed: skipped"; exit 77; }
/usr/bin/python3 -c 'import matplotlib, h5py' 2> /dev/null || { echo "matplotlib/h5py missing: skipped"; exit 77; }
rm -rf "$work"; mkdir -p "$work"
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
camp() { make -s -C "$src" -j2 campaign SIZE=smoke BUILD="$build" RES="$work/results" RUNS="$work/runs" "$@"; }

# 1. the whole smoke campaign
camp > "$work/run1.log" 2>&1; rc=$?
[ $rc -eq 0 ] || { tail -30 "$work/run1.log" >&2; fail "make campaign exit status $rc"; }
scores=$work/results/scores.json
[ -s "$scores" ] || { fail "no $scores"; echo "$fails failure(s)" >&2; exit 1; }
expected=0 expected_cmp=0 expected_ekm=0 no_noise='[]'
for ini in "$src"/scenarios/*.ini; do
  # the campaign's scenarios: [dem] and [compare] in the file itself
  js=$("$build/continuum/ekm" scenario "$ini" --engine lammps --size smoke --json) ||
    { fail "ekm scenario $ini failed"; continue; }
  jq -e '[.keys | to_entries[] | select(.value.from != "default") | .key | split(".")[0]]
         | index("dem") != null and index("compare") != null' <<< "$js" > /dev/null || continue
  f=$(jq -r '.keys["compare.fields"].value' <<< "$js")
  # [compare] noise = none (a 2D pile, one run at rest): no noise-normalised error
  [ "$(jq -r '.keys["compare.noise"].value' <<< "$js")" = none ] &&
    no_noise=$(jq -c --arg s "$(basename "$ini" .ini)" '. + [$s]' <<< "$no_noise")
  n=$(echo "$f" | tr ',' '\n' | grep -c .)
  np=$(jq '.points | length' <<< "$js")
  expected=$((expected + n * np))   # every field at every smoke sweep point
  # comparisons per row: EKM vs each engine that can run it, and engine vs
  # engine when both can (LIGGGHTS cannot run the Lees-Edwards scenarios)
  s=$(basename "$ini" .ini); nc=1
  [ -r "$src/dem_inputs/liggghts/$s.in" ] && [ ! -e "$src/dem_inputs/liggghts/$s.unsupported" ] && nc=3
  expected_cmp=$((expected_cmp + n * np * nc))
  expected_ekm=$((expected_ekm + n * np * (nc == 3 ? 2 : 1)))   # EKM vs an engine
done
rows=$(jq '.rows | length' "$scores")
[ "$rows" -eq "$expected" ] && [ "$rows" -gt 0 ] || fail "score table has $rows rows, expected $expected"
bad=$(jq --argjson nn "$no_noise" '[.rows[] | (.scenario | IN($nn[])) as $none
           | (.ekm_vs_liggghts, .ekm_vs_lammps, .liggghts_vs_lammps)
           | select(.status != "n/a")
           | select(.status != "ok" or (.rel_l2 | type) != "number"
                    or (.noise_normalised | type) != (if $none then "null" else "number" end))] | length' "$scores")
[ "$bad" -eq 0 ] || fail "$bad comparisons are missing or not finite in $scores (noise-normalised null only for $no_noise)"
[ "$no_noise" != '[]' ] || fail "no scenario with [compare] noise = none (the sand pile's 2D rows)"
# the 2D scenario's rows: scored by score2d, a map figure per point
for s in $(jq -r '.[]' <<< "$no_noise"); do
  for j in "$work"/results/"$s"/*/score_ekm_lammps.json; do
    jq -e '.tool == "ekmcompare score2d" and (.fields.szz.interior | not)' "$j" > /dev/null ||
      fail "$j: expected a score2d score (a cg map: no interior region)"
  done
  ls "$work"/results/figures/maps_"$s"_*.png > /dev/null 2>&1 || fail "no map figure of $s"
done
okn=$(jq '[.rows[] | (.ekm_vs_liggghts, .ekm_vs_lammps, .liggghts_vs_lammps) | select(.status == "ok")] | length' "$scores")
[ "$okn" -eq "$expected_cmp" ] || fail "$okn comparisons made, expected $expected_cmp"
grep -q "| chute | - | phi |" "$work/results/scores.md" || fail "scores.md has no chute phi row"
# the calibration: the smoke training set `rheology` (simple_shear's and
# simple_shear_p's smoke points, eta0 and eps0) is fitted, every point is
# run and scored with it, and the train/test matrix has finite cells
fit=$work/results/calibration/rheology/fit.json
jq -e '(.params | keys) == ["eps0", "eta0"] and (.chi2_dof | type) == "number" and .dof > 0
       and ([.points[] | .residuals.P, .residuals.sxz, .residuals.T | type == "number"] | all)' "$fit" > /dev/null ||
  fail "$fit: no fit of eta0 and eps0 with finite chi2/dof and residuals"
grep -q '^eta0 *=' "$work/results/calibration/rheology/fit.ini" || fail "no [material] eta0 in the fitted fit.ini"
# like for like: simple_shear_p's points ran under a barostat and are fitted
# under pressure control, simple_shear's under volume control
jq -e '([.points[] | select(.file | test("/simple_shear_p/")) | .control == "pressure"] | (length > 0 and all))
       and ([.points[] | select(.file | test("/simple_shear/")) | .control == "volume"] | (length > 0 and all))' \
  "$fit" > /dev/null || fail "$fit: expected simple_shear_p's points under pressure control, simple_shear's under volume control"
# every comparison with the fitted set is made: a score, or `not_steady`
# when the EKM with that set reaches no steady state in its run (the smoke
# set's chute: docs/campaign.md); the training scenarios' are all scores
okr=$(jq '[.rows[] | (.ekm_rheology_vs_liggghts, .ekm_rheology_vs_lammps)
           | select((.status == "ok" and (.rel_l2 | type) == "number") or .status == "not_steady")] | length' "$scores")
[ "$okr" -eq "$expected_ekm" ] || fail "$okr comparisons with the fitted set, expected $expected_ekm"
jq -e '[.rows[] | select(.scenario | startswith("simple_shear")) | .ekm_rheology_vs_lammps.status == "ok"] | (length > 0 and all)' \
  "$scores" > /dev/null || fail "$scores: a training point of the fitted set without a score"
cal=$work/results/calibration.json
jq -e '(.sets | map(.name)) == ["thesis", "rheology", "rheology_ekm_jam", "rheology_mu_i"]
       and ([.matrix[][] | (.rel_l2 | type == "number") or (.rel_l2 == null and (.not_steady > 0 or .no_solver or .not_taken))] | all)
       and .matrix.rheology.simple_shear.train and .matrix.rheology.simple_shear_p.train
       and (.matrix.rheology.chute.train | not) and (.matrix.thesis.simple_shear.train | not)
       and .sets[1].fitted.params.eta0.value > 0
       and ([.matrix[][] | .no_solver] | any | not)
       and ([.matrix.rheology_ekm_jam[] | .not_taken == null] | all)
       and (.matrix.rheology_mu_i | ([.chute, .shear_cell, .simple_shear_p] | map(.not_taken == null and (.rel_l2 | type == "number")) | all)
            and ([.filling, .simple_shear] | map(.not_taken | type == "string") | all))' \
  "$cal" > /dev/null ||
  fail "$cal: expected sets thesis, rheology and its closure sets, every cell finite (mu_i: the dense slabs only), the training cells marked"
grep -q "^| rheology | " "$work/results/calibration.md" || fail "calibration.md has no rheology row"
# the like-for-like matrix over phi, vx and P (mu_i has no T)
grep -q "^Like for like" "$work/results/calibration.md" || fail "calibration.md has no like-for-like matrix"
jq -e '.matrix.rheology_mu_i.chute.rel_l2_no_T | type == "number"' "$cal" > /dev/null ||
  fail "$cal: no like-for-like (phi, vx, P) cell of mu_i on the chute"
grep -q "^| rheology_mu_i | .*n/a (not taken)" "$work/results/calibration.md" || fail "calibration.md has no mu_i row with its n/a cells"
grep -q "^- rheology_mu_i, filling: .*is not what closure mu_i's slab solver takes" "$work/results/calibration.md" ||
  fail "calibration.md does not say why mu_i does not run the filling"
# the closure sets ([campaign] fit_closures): each fitted on the same points
# with its own constants; ekm_jam's run and scored at every point, mu_i's
# fitted without T (it has no temperature)
jq -e '.closure == "ekm_jam" and (.params | has("phi_J") and has("beta") and has("eta0"))
       and ([.points[] | .residuals.T | type == "number"] | all)' \
  "$work/results/calibration/rheology_ekm_jam/fit.json" > /dev/null || fail "no ekm_jam fit with phi_J, beta and T"
jq -e '.closure == "mu_i" and (.params | keys) == ["mu_2", "mu_s", "phi_max", "phi_min"]
       and ([.points[] | .residuals | has("T") | not] | all)' \
  "$work/results/calibration/rheology_mu_i/fit.json" > /dev/null || fail "no mu_i fit of its four smoke constants without T"
okj=$(jq '[.rows[] | (.ekm_rheology_ekm_jam_vs_liggghts, .ekm_rheology_ekm_jam_vs_lammps)
           | select((.status == "ok" and (.rel_l2 | type) == "number") or .status == "not_steady")] | length' "$scores")
[ "$okj" -eq "$expected_ekm" ] || fail "$okj comparisons with the ekm_jam set, expected $expected_ekm"
# mu_i's slab solver: every comparison of the dense slabs (a score, T n/a:
# no points), none of the others
jq -e '([.rows[] | select(.scenario == "chute" or .scenario == "shear_cell" or .scenario == "simple_shear_p")
         | (.ekm_rheology_mu_i_vs_liggghts, .ekm_rheology_mu_i_vs_lammps) | select(.status != "n/a")
         | .status == "ok" or .status == "not_steady"] | (length > 0 and all))
       and ([.rows[] | select(.field == "T" and .scenario == "chute") | .ekm_rheology_mu_i_vs_lammps
             | .status != "ok" or .rel_l2 == null] | all)
       and ([.rows[] | select(.scenario == "filling" or .scenario == "simple_shear") | has("ekm_rheology_mu_i_vs_lammps")]
            | any | not)' "$scores" > /dev/null ||
  fail "$scores: expected mu_i scored at every point of the chute, shear_cell and simple_shear_p (T n/a), none elsewhere"
grep -q "^## By parameter set" "$work/results/scores.md" || fail "scores.md has no table by parameter set"
figs=$work/results/figures/figures.txt
[ -s "$figs" ] || fail "no figures listed in $figs"
while read -r f; do [ -s "$work/results/figures/$(basename "$f")" ] || fail "figure $f missing or empty"; done < "$figs"

# 2. nothing to do right after
camp > "$work/run2.log" 2>&1 || fail "second make campaign failed"
grep -q "everything is up to date" "$work/run2.log" || fail "second run did work: $(grep -m3 'campaign:' "$work/run2.log")"

# 3. touching one scenario redoes that scenario only (mtime restored after)
touch -r "$src/scenarios/chute.ini" "$work/chute.mtime"
touch "$src/scenarios/chute.ini"
camp > "$work/run3.log" 2>&1 || fail "third make campaign failed"
touch -r "$work/chute.mtime" "$src/scenarios/chute.ini"
grep -q "campaign: EKM chute" "$work/run3.log" || fail "touching chute.ini did not redo the chute EKM run"
grep -q "campaign: CG chute" "$work/run3.log" || fail "touching chute.ini did not redo the chute coarse-graining"
grep -E "campaign: (DEM|CG|EKM) (filling|shear_cell|simple_shear)" "$work/run3.log" && fail "touching chute.ini redid other scenarios"
grep -q "chute.*is done (status ok)" "$work/run3.log" || fail "touching chute.ini re-ran its DEM (inputs unchanged)"
[ -s "$work/runs/chute/lammps-smoke/atoms.dump" ] || fail "the chute DEM run folder is gone"

# 4. a failing engine: reported with its log, the rest goes on
printf '#!/bin/sh\necho "ERROR: fake engine for the campaign test" \nexit 1\n' > "$work/fake_liggghts"
chmod +x "$work/fake_liggghts"
LIGGGHTS_EXE=$work/fake_liggghts make -s -C "$src" -j2 campaign SIZE=smoke BUILD="$build" \
  RES="$work/results_fail" RUNS="$work/runs_fail" ENGINES=liggghts > "$work/run4.log" 2>&1 &&
  fail "a failing DEM engine gave exit status 0"
# make's own status is 2 on any failure; campaign.sh's (a failed step: 4,
# docs/exit-codes.md) is in make's error line
grep -q "\] Error 4$" "$work/run4.log" ||
  fail "a failing DEM engine did not give campaign.sh exit status 4: $(grep -m1 'Error [0-9]' "$work/run4.log")"
grep -q "DEM FAILED: chute liggghts smoke (run.sh exit 4); log: .*screen.txt" "$work/run4.log" ||
  fail "the failed DEM run is not reported with its log: $(grep -m2 FAILED "$work/run4.log")"
[ -s "$work/results_fail/filling/ekm.h5" ] || fail "the EKM steps did not go on after the DEM failure"
jq -e '.rows[0].ekm_vs_liggghts.status == "missing"' "$work/results_fail/scores.json" > /dev/null ||
  fail "the table does not mark the failed comparison missing"

[ $fails -eq 0 ] || { echo "$fails failure(s)" >&2; exit 1; }
echo "campaign_test: all passed"
