#!/usr/bin/env bash
# runner_inputs.sh CASE SOURCE_DIR BUILD_DIR WORK_DIR: the DEM runner
# (scripts/dem/run.sh) records what a run produced and refuses what it was
# not meant to take (issue 13). No DEM is run: the engine is a stand-in
# writing a fixture dump, and the -s checks stop before any run (-l).
# CASE:
#   dumps_recorded  run.json records frames, bytes and sha256 of each dump;
#                   a finished run whose dump was cut after it is run again
#                   (not "done"), and check_run.sh refuses it (exit 2)
#   set_values      -s with a bad value, an unknown key, or no '=' fails as
#                   the scenario reader does: exit 2, one line naming it
set -u
case=$1 src=$2 build=$3 work=$4/$1
command -v jq > /dev/null || { echo "jq not installed: skipped"; exit 77; }
rm -rf "$work"; mkdir -p "$work"
export EKMSCENARIO=$build/scenario/ekmscenario
run=$src/scripts/dem/run.sh
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
case $case in
  dumps_recorded)
    printf '#!/bin/sh\ncase "$1" in -h) echo "LAMMPS (2 Aug 2023)"; exit 0 ;; esac\ncp %q atoms.dump\ngzip -cd %q > pairs.dump\necho log > log.txt\necho "EKMDEM_DONE natoms 2 steps 1000"\n' \
      "$src/tests/compare/fixtures/liggghts_example.dump" "$src/tests/compare/fixtures/chute_lammps_pairs.dump.gz" > "$work/fake_lmp"
    chmod +x "$work/fake_lmp"
    export LAMMPS_EXE=$work/fake_lmp
    d=$work/runs/collision/lammps-smoke
    "$run" -o "$work/runs" collision lammps smoke > "$work/run1.log" 2>&1 || fail "the stand-in run failed: $(tail -3 "$work/run1.log")"
    for f in atoms.dump pairs.dump; do
      jq -e --arg f "$f" --argjson fr "$(grep -c '^ITEM: TIMESTEP' "$d/$f")" --argjson by "$(stat -c %s "$d/$f")" \
        --arg sh "$(sha256sum "$d/$f" | cut -d' ' -f1)" '.dumps[$f] == {frames: $fr, bytes: $by, sha256: $sh}' "$d/run.json" > /dev/null ||
        fail "$d/run.json does not record $f (frames, bytes, sha256): $(jq -c .dumps "$d/run.json" 2>&1)"
    done
    "$run" -o "$work/runs" collision lammps smoke > "$work/run2.log" 2>&1
    grep -q "is done (status ok)" "$work/run2.log" || fail "an intact finished run is not kept: $(cat "$work/run2.log")"
    truncate -s 100 "$d/atoms.dump"
    "$src/scripts/dem/check_run.sh" "$d" > "$work/check.log" 2>&1; rc=$?
    [ $rc -eq 2 ] || fail "check_run.sh on a cut dump: exit $rc, expected 2"
    grep -q "atoms.dump: frames 1 (run.json: 2), bytes 100 (run.json: [0-9]*), sha256 .*: the dump changed after the run" "$work/check.log" ||
      fail "check_run.sh does not say how the dump differs: $(cat "$work/check.log")"
    "$run" -o "$work/runs" collision lammps smoke > "$work/run3.log" 2>&1 || fail "the run again failed"
    grep -q "is done" "$work/run3.log" && fail "a run whose dump was cut is taken as done"
    grep -q "atoms.dump: frames 1 (run.json: 2), bytes 100 .*: the dump changed after the run" "$work/run3.log" &&
      grep -q "its dumps are not what the run produced: running again" "$work/run3.log" ||
      fail "run.sh does not say why it runs again: $(cat "$work/run3.log")"
    [ "$(stat -c %s "$d/atoms.dump")" -gt 100 ] || fail "the cut dump was not made again" ;;
  set_values)
    # -s VALUE, expected error line (the reader's, naming the key)
    while IFS='|' read -r s want; do
      "$run" -l -o "$work/runs" -s "$s" chute lammps smoke > "$work/out.txt" 2> "$work/err.txt"; rc=$?
      [ $rc -eq 2 ] || fail "-s '$s': exit $rc, expected 2 ($(cat "$work/err.txt"))"
      [ "$(wc -l < "$work/err.txt")" -eq 1 ] && grep -qF -- "$want" "$work/err.txt" ||
        fail "-s '$s': expected one line with '$want', got: $(cat "$work/err.txt")"
      [ -s "$work/out.txt" ] && fail "-s '$s': the sweep points were listed anyway"
      [ -e "$work/runs" ] && fail "-s '$s': an output folder was made"
    done <<'LIST'
smoke.t_flow=nan|--set dem.smoke.t_flow: [dem] smoke.t_flow: expected a number, got 'nan'
t_flow=-1|--set dem.t_flow: [dem] t_flow: expected a time > 0 [s], got '-1'
nosuchkey=1|--set dem.nosuchkey: [dem] nosuchkey: unknown key
foo|-s 'foo': expected KEY=VALUE
=1|-s '=1': expected KEY=VALUE
t_flow=1e400|[dem] t_flow: expected a number, got '1e400'
LIST
    ;;
  *) echo "unknown case $case" >&2; exit 1 ;;
esac
[ $fails -eq 0 ] || { echo "$fails failure(s) (logs in $work)" >&2; exit 1; }
echo "runner_inputs $case: all passed"
