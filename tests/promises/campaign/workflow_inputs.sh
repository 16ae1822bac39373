#!/usr/bin/env bash
# workflow_inputs.sh CASE SOURCE_DIR BUILD_DIR WORK_DIR: the campaign notices
# inputs that changed after the step that used them (issue 13). A scratch
# campaign of the chute at smoke size whose DEM engines are stand-ins
# copying the chute fixture dumps (tests/compare/fixtures: no DEM is run),
# coarse-grained and scored engine against engine (no EKM run), through
# workflow/Snakefile with the options of scripts/campaign/campaign.sh.
# CASE:
#   dump_truncated   a dump cut to half after the run, its mtime kept: the
#                    DEM runs recorded frames, bytes and sha256 in run.json;
#                    the campaign is not "up to date", its CG step fails
#                    with one line naming the dump and what differs, and the
#                    table marks the score of the removed cg file missing
#   table_input_changed  a cg file changed (mtime kept) after its score: the
#                    table marks the score "missing (input changed)"
#   table_input_gone a cg file deleted after a campaign, FROM_CG=1: the table
#                    is made again and marks the score "missing (input gone)"
#   stale_tmp        a step's OUTPUT.tmp.PID of a process that is gone is
#                    removed (and said so), one of a live process kept
set -u
case=$1 src=$2 build=$3 work=$4/$1
for c in snakemake jq; do command -v $c > /dev/null || { echo "$c not installed: skipped"; exit 77; }; done
rm -rf "$work"; mkdir -p "$work/wd"
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
res=$work/res runs=$work/runs
fixtures=$src/tests/compare/fixtures
# the stand-in engines: answer -h as the real ones, write the fixture dump
# of their engine and the completion marker
for e in lammps liggghts; do
  ver=$([ $e = lammps ] && echo "LAMMPS (2 Aug 2023)" || echo "LIGGGHTS-PUBLIC 3.8.0")
  printf '#!/bin/sh\ncase "$1" in -h) echo "%s"; exit 0 ;; esac\ngzip -cd %q > atoms.dump\ngzip -cd %q > pairs.dump\necho "EKMDEM_DONE natoms 4552 steps 35000"\n' \
    "$ver" "$fixtures/chute_${e}_atoms.dump.gz" "$fixtures/chute_${e}_pairs.dump.gz" > "$work/fake_$e"
  chmod +x "$work/fake_$e"
done
smk() { # smk FROM_CG TARGET...: the workflow as campaign.sh runs it
  local from=$1; shift
  LAMMPS_EXE=$work/fake_lammps LIGGGHTS_EXE=$work/fake_liggghts \
    snakemake --snakefile "$src/workflow/Snakefile" -d "$work/wd" -j1 \
      --config size=smoke "engines=liggghts lammps" np=1 "res=$res" "runs=$runs" "build=$build" scenarios=chute \
               "from_cg=$from" \
      --quiet progress rules --rerun-triggers mtime --drop-metadata --rerun-incomplete --keep-going "$@"
}
score=$res/chute/score_liggghts_lammps.json
row() { jq -c '.rows[] | select(.scenario == "chute" and .field == "phi") | .liggghts_vs_lammps' "$res/scores.json"; }

# a campaign: both DEM runs, both cg files, the engine score, the table
smk 0 "$score" > "$work/run1.log" 2>&1 || { tail -20 "$work/run1.log" >&2; fail "the scratch campaign failed"; }
smk 0 --allowed-rules table -- "$res/scores.json" > "$work/table1.log" 2>&1 || { tail -20 "$work/table1.log" >&2; fail "the table failed"; }
[ "$(row | jq -r .status)" = ok ] || { fail "the first table has no score: $(row)"; exit 1; }

case $case in
  dump_truncated)
    d=$runs/chute/lammps-smoke
    # the record: frames, bytes and sha256 of each dump in run.json
    jq -e --argjson fr "$(grep -c '^ITEM: TIMESTEP' "$d/atoms.dump")" --argjson by "$(stat -c %s "$d/atoms.dump")" \
      --arg sh "$(sha256sum "$d/atoms.dump" | cut -d' ' -f1)" \
      '.dumps["atoms.dump"] == {frames: $fr, bytes: $by, sha256: $sh} and (.dumps["pairs.dump"].sha256 | length) == 64' \
      "$d/run.json" > /dev/null || fail "$d/run.json: no record of atoms.dump (frames, bytes, sha256): $(jq -c .dumps "$d/run.json")"
    cp "$res/chute/dem_lammps.json" "$work/manifest.json"
    smk 0 -n "$score" "$res/scores.json" > "$work/dry1.log" 2>&1
    grep -q "Nothing to be done" "$work/dry1.log" || fail "a finished scratch campaign is not up to date: $(grep -m3 . "$work/dry1.log")"
    # the dump cut to half after the run, its mtime kept
    touch -r "$d/atoms.dump" "$work/mtime"
    truncate -s $(( $(stat -c %s "$d/atoms.dump") / 2 )) "$d/atoms.dump"
    touch -r "$work/mtime" "$d/atoms.dump"
    smk 0 -n "$score" "$res/scores.json" > "$work/dry2.log" 2>&1
    grep -q "Nothing to be done" "$work/dry2.log" && fail "a truncated dump: the campaign says it is up to date"
    grep -qE '^cg +1 ' "$work/dry2.log" || fail "a truncated dump: its CG step is not redone: $(grep -m5 . "$work/dry2.log")"
    # the steps, then the table (campaign.sh's two invocations, the second
# only the table's rule)
    smk 0 "$score" > "$work/run2.log" 2>&1 && fail "a truncated dump: the campaign's steps exit 0"
    smk 0 --allowed-rules table -- "$res/scores.json" > "$work/table2.log" 2>&1
    n=$(grep -c "^campaign: CG chute lammps: .*lammps-smoke/atoms.dump: frames 1 (run.json: 2), bytes [0-9]* (run.json: [0-9]*), sha256 .*: the dump changed after the run" "$work/run2.log")
    [ "$n" -eq 1 ] || fail "the CG step does not say once which dump changed and how: $(grep -m3 -i 'campaign: CG\|error' "$work/run2.log")"
    [ -e "$res/chute/cg_lammps.h5" ] && fail "the cg file of the truncated dump is still there"
    [ "$(row | jq -r '.status + " " + .reason')" = "missing input gone" ] ||
      fail "the table still shows the score of the removed cg file: $(row)"
    grep -q "| chute | - | phi | .* | missing (input gone) |$" "$res/scores.md" ||
      fail "scores.md does not mark the row missing (input gone): $(grep '| chute | - | phi' "$res/scores.md")"
    # the step itself: exit 4, one line
    cp "$work/manifest.json" "$d/run.json"
    "$src/scripts/campaign/cg_step.sh" "$d" "chute lammps" "$work/x.h5" "$work/x.json" "$build/compare/ekmcompare" 1e-5 \
      > "$work/step.out" 2> "$work/step.err"; rc=$?
    [ $rc -eq 4 ] || fail "cg_step.sh on a truncated dump: exit $rc, expected 4"
    [ "$(wc -l < "$work/step.err")" -eq 1 ] || fail "cg_step.sh on a truncated dump: not one line: $(cat "$work/step.err")"
    [ -e "$work/x.h5" ] || [ -e "$work/x.json" ] && fail "cg_step.sh on a truncated dump wrote an output" ;;
  table_input_changed)
    # the record (the path as the score names it: relative to the checkout when inside)
    jq -e --arg s "$(sha256sum "$res/chute/cg_liggghts.h5" | cut -d' ' -f1)" --arg p "${res#"$src"/}/chute/cg_liggghts.h5" \
      '.inputs.ekm == {path: $p, sha256: $s}' "$score" > /dev/null ||
      fail "$score: no record of its input cg_liggghts.h5: $(jq -c .inputs "$score")"
    touch -r "$res/chute/cg_liggghts.h5" "$work/mtime"
    printf 'x' >> "$res/chute/cg_liggghts.h5"
    touch -r "$work/mtime" "$res/chute/cg_liggghts.h5"
    # the table made again (as after any step), from the same score files
    rm "$res/scores.json"
    smk 0 --allowed-rules table -- "$res/scores.json" > "$work/table2.log" 2>&1 ||
      fail "the table was not made: $(tail -5 "$work/table2.log")"
    [ "$(row | jq -r '.status + " " + .reason')" = "missing input changed" ] ||
      fail "the table shows a score whose input changed: $(row)"
    grep -q "| chute | - | phi | .* | missing (input changed) |$" "$res/scores.md" ||
      fail "scores.md does not mark the row missing (input changed): $(grep '| chute | - | phi' "$res/scores.md")" ;;
  table_input_gone)
    rm "$res/chute/cg_liggghts.h5"
    # as campaign.sh with FROM_CG=1: the steps, then the table
    smk 1 "$score" > "$work/run2.log" 2>&1
    smk 1 --allowed-rules table -- "$res/scores.json" > "$work/table2.log" 2>&1 || fail "the table was not made: $(tail -5 "$work/table2.log")"
    grep -q "score_liggghts_lammps.json: its input .*cg_liggghts.h5 is gone: the table is made again" "$work/run2.log" ||
      fail "the campaign does not say the score's input is gone: $(grep -m3 campaign: "$work/run2.log")"
    [ "$(row | jq -r '.status + " " + .reason')" = "missing input gone" ] ||
      fail "the table still shows the score of a deleted cg file: $(row)"
    grep -q "| chute | - | phi | .* | missing (input gone) |$" "$res/scores.md" ||
      fail "scores.md still shows the old row: $(grep '| chute | - | phi' "$res/scores.md")" ;;
  stale_tmp)
    sh -c 'exit 0' & gone=$!; wait $gone
    : > "$res/chute/cg_lammps.h5.tmp.$gone"                  # a cg step killed
    : > "$res/chute/score_ekm_lammps.json.tmp.$gone.tmp.$gone" # ekmcompare under a killed score step
    : > "$res/chute/score_ekm_liggghts.json.tmp.$$"           # a live process's: kept
    : > "$res/chute/dem_liggghts.json.tmp.$$"                 # of a step about to run: removed by it
    touch "$runs/chute/liggghts-smoke/atoms.dump"              # newer: its CG is redone
    smk 0 "$score" > "$work/run2.log" 2>&1 || fail "the campaign failed: $(tail -5 "$work/run2.log")"
    for f in cg_lammps.h5.tmp.$gone score_ekm_lammps.json.tmp.$gone.tmp.$gone; do
      [ -e "$res/chute/$f" ] && fail "stale temporary $f (process $gone gone) not removed"
      grep -q "^campaign: removed stale temporary $res/chute/$f (process $gone is gone)" "$work/run2.log" ||
        fail "the removal of $f is not reported"
    done
    [ -e "$res/chute/dem_liggghts.json.tmp.$$" ] && fail "the CG step did not remove its own output's temporary"
    grep -q "^campaign: removed stale temporary $res/chute/dem_liggghts.json.tmp.$$ (left by an interrupted step" "$work/run2.log" ||
      fail "the CG step's removal of its temporary is not reported"
    [ -e "$res/chute/score_ekm_liggghts.json.tmp.$$" ] || fail "the temporary of a live process was removed" ;;
  *) echo "unknown case $case" >&2; exit 1 ;;
esac
[ $fails -eq 0 ] || { echo "$fails failure(s) (logs in $work)" >&2; exit 1; }
echo "workflow_inputs $case: all passed"
