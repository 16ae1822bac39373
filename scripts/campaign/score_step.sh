#!/usr/bin/env bash
# score_step.sh: one score of the campaign (rules score_ekm, score_ekm_set,
# score_engines of workflow/Snakefile), with a record of its inputs.
#   score_step.sh OUT EKMCOMPARE score|score2d ARG...   (run from the checkout)
# Takes the SHA-256 of the two files the score reads (its --dem and --ekm;
# score2d's --dem and --model), runs `EKMCOMPARE score ARG... --dem-sha256
# S --ekm-sha256 S -o OUT.tmp.PID`
# (ekmcompare writes them into the score's "inputs": {"dem": {"path",
# "sha256"}, "ekm": {...}}), checks that neither input changed meanwhile,
# and moves the score to OUT: OUT is whole or absent. table.sh recomputes
# the checksums and marks a score whose input is gone or changed missing
# instead of showing its numbers. Temporaries of OUT left by an
# interrupted step are removed first.
# Exit status (docs/exit-codes.md): 1 usage, 3 OUT cannot be written or an
# input cannot be read, 4 an input changed while it was scored (an input
# that no longer matches), else ekmcompare's.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
usage="usage: score_step.sh OUT EKMCOMPARE score|score2d ARG... (with --dem CG.h5 and --ekm RUN.h5, score2d's --model RUN.h5)"
if [ $# -lt 3 ] || { [ "$3" != score ] && [ "$3" != score2d ]; }; then echo "score_step.sh: $usage" >&2; exit 1; fi
model_flag=--ekm; [ "$3" = score2d ] && model_flag=--model
out=$1; shift
dem="" ekm="" prev=""
for a in "${@:3}"; do
  case $prev in --dem) dem=$a ;; "$model_flag") ekm=$a ;; esac
  prev=$a
done
if [ -z "$dem" ] || [ -z "$ekm" ]; then echo "score_step.sh: $usage" >&2; exit 1; fi
"$here/stale_temps.sh" before "$out" || exit
tmp=$out.tmp.$$
trap 'rm -f "$tmp"' EXIT
trap 'exit 130' INT; trap 'exit 143' TERM; trap 'exit 129' HUP
# the digest alone (from stdin: no escaped file name in front of it)
sum() { local s; s=$(sha256sum < "$1") || return 3; echo "${s%% *}"; }
if ! ds=$(sum "$dem") || ! es=$(sum "$ekm"); then
  echo "score_step.sh: $dem, $ekm: cannot read the score's inputs" >&2; exit 3
fi
"$@" --dem-sha256 "$ds" --ekm-sha256 "$es" -o "$tmp" > /dev/null || exit
if ! ds2=$(sum "$dem") || ! es2=$(sum "$ekm"); then
  echo "score_step.sh: $dem, $ekm: cannot read the score's inputs after scoring: $out not written" >&2; exit 3
fi
if [ "$ds2" != "$ds" ] || [ "$es2" != "$es" ]; then
  echo "score_step.sh: $dem or $ekm changed while it was scored: $out not written" >&2; exit 4
fi
mv -- "$tmp" "$out" || { echo "score_step.sh: $out: cannot write the score" >&2; exit 3; }
