#!/usr/bin/env bash
# cg_step.sh: the coarse-graining step of the campaign for one point and
# engine (rule cg of workflow/Snakefile).
#   cg_step.sh RUN_DIR WORDS H5 MANIFEST EKMCOMPARE DT [CG_OPTION...]
# Checks the run's atoms.dump against what the run recorded in its run.json
# (frames, bytes, sha256: scripts/dem/dump_record.sh) before using it: a
# dump that changed after the run (truncated, edited) is a failed input,
# one line naming the file and what differs, exit 4, and nothing is
# written. Then `ekmcompare cg RUN_DIR/atoms.dump --dt DT
# [--expect-snapshots FRAMES] CG_OPTION... -o H5` and RUN_DIR/run.json
# copied (atomically) to MANIFEST. Temporaries of
# H5 and MANIFEST left by an interrupted step are removed first.
# Exit status (docs/exit-codes.md): 1 usage, 3 no dump or run.json,
# 4 the dump is not what the run produced, else ekmcompare's.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
[ $# -ge 6 ] || { echo "cg_step.sh: usage: cg_step.sh RUN_DIR WORDS H5 MANIFEST EKMCOMPARE DT [CG_OPTION...]" >&2; exit 1; }
run=$1 words=$2 h5=$3 manifest=$4 ekmc=$5 dt=$6; shift 6
"$here/stale_temps.sh" before "$h5" "$manifest" || exit
if [ ! -r "$run/atoms.dump" ]; then
  echo "campaign: $run/atoms.dump: no dump (did the DEM step run?)" >&2; exit 3
fi
chk=$("$root/scripts/dem/dump_record.sh" verify "$run" atoms.dump 2>&1); rc=$?
if [ $rc -ne 0 ]; then
  # the checker's line, as the campaign's: what differs, and what to do
  redo=$(jq -r '"make dem SCENARIO=\(.scenario) ENGINE=\(.engine) SIZE=\(.size)"' "$run/run.json" 2> /dev/null) ||
    redo="make dem"
  echo "campaign: CG $words: ${chk#dump_record.sh: }; run the DEM again ($redo) or restore the dump" >&2
  exit $rc
fi
[ -z "$chk" ] || echo "campaign: CG $words: ${chk#dump_record.sh: }" >&2
# the recorded frame count: a snapshot cut short is then ekmcompare's error
frames=$(jq -r '.dumps["atoms.dump"].frames // empty' "$run/run.json" 2> /dev/null)
expect=(); [ -n "$frames" ] && expect=(--expect-snapshots "$frames")
"$ekmc" cg "$run/atoms.dump" --dt "$dt" "${expect[@]}" "$@" -o "$h5" || exit
cp "$run/run.json" "$manifest.tmp.$$" && mv "$manifest.tmp.$$" "$manifest" ||
  { rm -f "$manifest.tmp.$$"; echo "campaign: $manifest: cannot write the run manifest" >&2; exit 3; }
