#!/usr/bin/env bash
# parse_error_test.sh: a campaign whose workflow does not parse because the
# scenario reader refuses a scenario exits with the reader's status (2, bad
# input) and shows the reader's one error line, not a Python traceback.
#   parse_error_test.sh SOURCE_DIR WORK_DIR
# The reader is a stand-in `ekmscenario` (in a scratch build folder) that
# refuses every scenario as the real one refuses an unknown key; no step runs.
set -u
src=$1 work=$2
command -v snakemake > /dev/null || { echo "snakemake not installed: skipped"; exit 77; }
rm -rf "$work"; mkdir -p "$work/build/continuum" "$work/build/compare" "$work/build/scenario"
line='scenarios/chute.ini:7: [dem] bogus: unknown key (expected one of the keys of docs/scenario-format.md)'
printf '#!/bin/sh\necho "ekmscenario: %s" >&2\nexit 2\n' "$line" > "$work/build/scenario/ekmscenario"
printf '#!/bin/sh\nexit 0\n' > "$work/build/compare/ekmcompare"
cp "$work/build/compare/ekmcompare" "$work/build/continuum/ekm"
chmod +x "$work/build/scenario/ekmscenario" "$work/build/continuum/ekm" "$work/build/compare/ekmcompare"
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }
"$src/scripts/campaign/campaign.sh" all smoke "liggghts lammps" 1 "$work/results" "$work/runs" "$work/build" 1 \
  > "$work/out.log" 2>&1
rc=$?
[ $rc -eq 2 ] || fail "exit status $rc, expected 2 (bad input)"
grep -qF "ekmscenario: $line" "$work/out.log" || fail "the reader's error line is not shown"
grep -q "Traceback\|SystemExit\|WorkflowError" "$work/out.log" && fail "a Python traceback is shown"
[ -e "$work/results/scores.json" ] && fail "a score table was written"
[ $fails -eq 0 ] || { cat "$work/out.log" >&2; echo "$fails failure(s)" >&2; exit 1; }
echo "parse_error_test: all passed"
