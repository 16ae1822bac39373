#!/usr/bin/env bash
# score_step.sh: one score of the campaign (rules score_ekm, score_ekm_set,
# score_engines of workflow/Snakefile), with a record of its inputs.
#   score_step.sh OUT EKMCOMPARE score ARG...   (run from the checkout)
# Runs `EKMCOMPARE score ARG... -o OUT.tmp.PID`, then adds to the score
# "inputs": {"dem": {"path", "sha256"}, "ekm": {"path", "sha256"}} for the
# two files it read (its "dem" and "ekm"), and moves it to OUT: OUT is
# whole or absent. table.sh recomputes the checksums and marks a score
# whose input is gone or changed missing instead of showing its numbers.
# Temporaries of OUT left by an interrupted step are removed first.
# Exit status (docs/exit-codes.md): 1 usage, 3 OUT cannot be written,
# 7 no jq, else ekmcompare's.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
[ $# -ge 3 ] || { echo "score_step.sh: usage: score_step.sh OUT EKMCOMPARE score ARG..." >&2; exit 1; }
out=$1; shift
command -v jq > /dev/null || { echo "score_step.sh: jq not installed (scripts/deps.sh base)" >&2; exit 7; }
"$here/stale_temps.sh" before "$out" || exit
tmp=$out.tmp.$$ rec=$out.rec.tmp.$$
trap 'rm -f "$tmp" "$rec"' EXIT
trap 'exit 130' INT; trap 'exit 143' TERM; trap 'exit 129' HUP
"$@" -o "$tmp" > /dev/null || exit
sum() { local s; s=$(sha256sum -- "$1") || return 3; echo "${s%% *}"; }
dem=$(jq -r '.dem // empty' "$tmp") && ekm=$(jq -r '.ekm // empty' "$tmp") && [ -n "$dem" ] && [ -n "$ekm" ] ||
  { echo "score_step.sh: $tmp: the score names no dem or ekm input" >&2; exit 5; }
ds=$(sum "$dem") && es=$(sum "$ekm") || { echo "score_step.sh: $dem, $ekm: cannot read the score's inputs" >&2; exit 3; }
# the record goes in as text before the closing brace: the score's numbers
# stay as ekmcompare printed them (jq would reformat them)
inputs=$(jq -cn --arg dp "$dem" --arg ds "$ds" --arg ep "$ekm" --arg es "$es" \
  '{dem: {path: $dp, sha256: $ds}, ekm: {path: $ep, sha256: $es}}') || exit 5
body=$(cat "$tmp") && [[ $body == *"}" ]] ||
  { echo "score_step.sh: $tmp: expected a JSON object from ekmcompare score" >&2; exit 5; }
body=${body%\}}; body=${body%$'\n'}
{ printf '%s,\n  "inputs": %s\n}\n' "$body" "$inputs" > "$rec" && jq -e .inputs "$rec" > /dev/null &&
  mv "$rec" "$out"; } || { echo "score_step.sh: $out: cannot write the score" >&2; exit 3; }
