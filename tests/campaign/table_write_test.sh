#!/usr/bin/env bash
# table_write_test.sh: scripts/campaign/table.sh that cannot write its table
# exits 3 (I/O, docs/exit-codes.md) with one line naming the file, and leaves
# no scores.json or scores.md.
#   table_write_test.sh SOURCE_DIR WORK_DIR
set -u
src=$1 work=$2
command -v jq > /dev/null || { echo "jq not installed: skipped"; exit 77; }
rm -rf "$work"; mkdir -p "$work/res"
echo '[{"scenario": "chute", "engines": ["lammps"], "fields": "phi", "points": [{"tag": "", "vars": {"theta": "24"}}]}]' > "$work/plan.json"
mkdir "$work/res/scores.json.tmp"   # a folder where the temporary goes: the write fails
"$src/scripts/campaign/table.sh" smoke "$work/res" lammps "$work/plan.json" > "$work/out.txt" 2> "$work/err.txt"
rc=$? fails=0
[ $rc -eq 3 ] || { echo "FAIL: exit status $rc, expected 3" >&2; fails=1; }
grep -qx "table.sh: $work/res/scores.json.tmp: cannot write the score table" "$work/err.txt" ||
  { echo "FAIL: no error line naming the file" >&2; fails=1; }
[ -e "$work/res/scores.json" ] || [ -e "$work/res/scores.md" ] && { echo "FAIL: a partial table was written" >&2; fails=1; }
[ $fails -eq 0 ] || { cat "$work/err.txt" >&2; exit 1; }
echo "table_write_test: all passed"
