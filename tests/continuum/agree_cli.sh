#!/usr/bin/env bash
# `ekm agree NEWTON.h5 RUN.h5 [--tol X]` (continuum/agree_cli.c), the
# campaign's test: simple_shear solved by `ekm steady` and run by `ekm run`
# to its steady state agree (exit 0, "agree: ..."); with --tol 0 they do
# not (exit 6, "disagree: ..."); a run that did not end steady disagrees;
# bad files and a bad command line give one error line and the exit code
# of docs/exit-codes.md.
#   tests/continuum/agree_cli.sh EKM SOURCE_DIR WORK_DIR
set -u
ekm=$1 src=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
# expect CODE PATTERN ARGS...: ekm agree ARGS exits CODE and prints PATTERN (stdout + stderr)
expect() {
  local code=$1 pattern=$2
  shift 2
  "$ekm" agree "$@" > "$work/out.txt" 2>&1
  local rc=$?
  [ "$rc" -eq "$code" ] || fail "ekm agree $*: exit $rc, expected $code ($(cat "$work/out.txt"))"
  grep -q -E -e "$pattern" "$work/out.txt" || fail "ekm agree $*: no '$pattern' in: $(cat "$work/out.txt")"
  [ "$(wc -l < "$work/out.txt")" -eq 1 ] || fail "ekm agree $*: not one line: $(cat "$work/out.txt")"
}
ini=$src/scenarios/simple_shear.ini
"$ekm" steady "$ini" -o "$work/newton.h5" --quiet || fail "ekm steady simple_shear"
"$ekm" run "$ini" -o "$work/run.h5" --quiet || fail "ekm run simple_shear"
"$ekm" run "$ini" --set run.t_end=0.1 -o "$work/short.h5" --quiet || fail "ekm run (short)"
expect 0 "^agree: largest difference .* of the run's maximum \((phi|vx|T|P); tolerance 0.05\)$" \
  "$work/newton.h5" "$work/run.h5"
expect 6 "^disagree: largest difference .*tolerance 0\)$" "$work/newton.h5" "$work/run.h5" --tol 0
expect 6 "^disagree: the time-stepped run did not end steady \(steady = 0\)$" "$work/newton.h5" "$work/short.h5"
"$ekm" run "$ini" --set run.stop=t_end --set run.t_end=0.1 -o "$work/tend.h5" --quiet || fail "ekm run (t_end)"
expect 6 "^disagree: the time-stepped run was not one to stop when steady" "$work/newton.h5" "$work/tend.h5"
expect 3 "no-such.h5" "$work/newton.h5" "$work/no-such.h5"
printf 'not hdf5\n' > "$work/text.h5"
expect 2 "text.h5" "$work/newton.h5" "$work/text.h5"
expect 1 "expected NEWTON.h5 RUN.h5" "$work/newton.h5"
expect 1 "--tol 'x': expected a number >= 0" "$work/newton.h5" "$work/run.h5" --tol x
[ "$fails" -eq 0 ] || exit 1
echo "agree_cli: ok"
