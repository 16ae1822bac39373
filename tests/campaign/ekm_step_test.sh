#!/usr/bin/env bash
# scripts/campaign/ekm_step.sh: a steady scenario's output is the Newton
# state (ekm steady: root attribute steady_solver) when it agrees with the
# time-stepped run, and the run's when Newton finds another steady state:
# at 30 degrees the chute runs to a fast dilute layer with a dilute top
# tail, Newton returns one without it (0.18 of the largest phi apart,
# docs/model/steady.md "Steady solver"); nothing of the step is left beside its
# output.
# Usage: ekm_step_test.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -uo pipefail
src=$1 build=$2 work=$3
ekm="$build/continuum/ekm"
rm -rf "$work" && mkdir -p "$work"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
solver() { /usr/bin/python3 -c "import h5py,sys; f=h5py.File(sys.argv[1]); print('steady' if 'steady_solver' in f.attrs else 'run', int(f.attrs['steady']))" "$1"; }
cd "$src" || exit 1
for angle in 22 30; do
  out="$work/chute$angle/ekm.h5"
  mkdir -p "$(dirname "$out")"
  log=$(scripts/campaign/ekm_step.sh "$ekm" steady "$out" scenarios/chute.ini --set gravity.angle=$angle 2>&1)
  rc=$?
  echo "$angle degrees: $log"
  [ $rc -eq 0 ] || fail "$angle degrees: exit $rc"
  [ -f "$out" ] && [ -f "${out%.h5}.xdmf" ] || fail "$angle degrees: no output"
  left=$(ls -A "$(dirname "$out")" | grep -v -x -e ekm.h5 -e ekm.xdmf)
  [ -z "$left" ] || fail "$angle degrees: left beside the output: $left"
  got=$(solver "$out")
  if [ $angle = 22 ]; then
    [ "$got" = "steady 1" ] || fail "22 degrees: expected the Newton state (steady 1), got $got"
    grep -q "agree: largest difference" <<<"$log" || fail "22 degrees: no agreement line"
  else
    [ "$got" = "run 1" ] || fail "30 degrees: expected the run's steady state (run 1), got $got"
    grep -q "found another steady state than ekm run" <<<"$log" || fail "30 degrees: no line naming the other state"
  fi
done
# a bad option: the programs' own error and exit code, no output
out="$work/bad/ekm.h5"
mkdir -p "$(dirname "$out")"
scripts/campaign/ekm_step.sh "$ekm" steady "$out" scenarios/chute.ini --set gravity.angle=abc > "$work/bad.log" 2>&1
rc=$?
[ $rc -eq 2 ] || fail "bad --set: exit $rc, expected 2"
[ -z "$(ls -A "$(dirname "$out")")" ] || fail "bad --set: left $(ls -A "$(dirname "$out")")"
[ $fails -eq 0 ] && echo "ekm_step_test: all passed"
exit $((fails > 0))
