#!/usr/bin/env bash
# model_run_test.sh: an EKM run made to stop when steady records whether it
# got there; `ekmcompare score` copies that into the score ("model_run") and
# the campaign's table marks a transient "not_steady" instead of scoring it
# as a steady state (issue 11, item 1).
#   model_run_test.sh EKM EKMCOMPARE SOURCE_DIR WORK_DIR
set -u
ekm=$1 ekmc=$2 src=$3 work=$4
command -v jq > /dev/null || { echo "jq not installed: skipped"; exit 77; }
rm -rf "$work"; mkdir -p "$work/res/simple_shear"; cd "$work" || exit 3
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
ini=$src/scenarios/simple_shear.ini
dem=$src/results/simple_shear/phi0.56-rate10/cg_lammps.h5
# steady at about 10 s (its [run] stop = steady, t_end 50 s); cut at 0.5 s
"$ekm" run "$ini" -o steady.h5 --quiet || fail "ekm run (to steady) failed"
"$ekm" run "$ini" --set run.t_end=0.5 -o cut.h5 --quiet || fail "ekm run (t_end 0.5 s) failed"
for k in steady cut; do
  "$ekmc" score --dem "$dem" --ekm $k.h5 --fields phi,T,P --ekm-time last -o $k.json --quiet > /dev/null ||
    fail "score of $k.h5 failed"
done
jq -e '.model_run.stop == "steady" and .model_run.steady == 1 and .model_run.steady_time_s > 0
       and .model_run.steady_time_s < 50' steady.json > /dev/null || fail "steady run: model_run $(jq -c .model_run steady.json)"
jq -e '.model_run.steady == 0 and .model_run.steady_time_s == null and .model_run.drift_per_s > 0' cut.json > /dev/null ||
  fail "cut run: model_run $(jq -c .model_run cut.json)"
# engine against engine (the model is a cg file): no model_run
"$ekmc" score --dem "$dem" --ekm "$dem" --fields phi --ekm-time last -o dem.json --quiet > /dev/null || fail "score dem vs dem failed"
jq -e '.model_run == null' dem.json > /dev/null || fail "a cg file as the model: model_run $(jq -c .model_run dem.json)"
# the table: the transient's cells are not_steady (fields and scalars), the steady run's ok
for k in steady cut; do
  cp $k.json res/simple_shear/score_ekm_lammps.json
  echo '[{"scenario": "simple_shear", "engines": ["lammps"], "fields": "phi,T,P", "points": [{"tag": "", "vars": {}}]}]' > plan.json
  "$src/scripts/campaign/table.sh" ref "$work/res" lammps "$work/plan.json" > /dev/null 2> table.err || fail "table.sh failed: $(cat table.err)"
  want=$([ $k = steady ] && echo ok || echo not_steady)
  jq -e --arg w "$want" '[.rows[].ekm_vs_lammps.status] | length == 3 and all(. == $w)' res/scores.json > /dev/null ||
    fail "$k: table cells $(jq -c '[.rows[].ekm_vs_lammps.status]' res/scores.json), expected $want"
done
grep -q "EKM not steady" res/scores.md || fail "scores.md does not say the EKM run is not steady"
[ $fails -eq 0 ] || { echo "$fails failure(s)" >&2; exit 1; }
echo "model_run_test: all passed"
