#!/usr/bin/env bash
# campaign.sh: `make campaign` (and campaign-table, figures): the
# Snakemake workflow workflow/Snakefile with the campaign's options.
#   campaign.sh all|table|figures SIZE "ENGINES" NP RES RUNS BUILD JOBS ["SCENARIOS"]
# SCENARIOS (blank-separated; empty: all): the campaign scenarios whose
# steps run (the Snakefile's config scenarios).
# all: removes the campaign's stale temporaries (an interrupted table or
# figure, a stamp, a killed step's OUTPUT.tmp.PID whose process is gone:
# scripts/campaign/stale_temps.sh) and names each, says "everything is up to date" when Snakemake has
# nothing to do, else runs the steps up to the scores (--keep-going: a
# failed step does not stop the others), then the table and the figures
# from the scores that exist (a second invocation, so that the workflow is
# parsed again and sees the scores just made). Exit status (docs/exit-codes.md):
# 4 if a step failed (Snakemake's messages and the failed step's log above),
# the workflow's own status if it does not parse (2 when the scenario reader
# refuses a scenario, with the reader's error line), 1 usage, 7 no snakemake.
set -uo pipefail
[ $# -eq 8 ] || [ $# -eq 9 ] || { echo "campaign.sh: usage: campaign.sh all|table|figures SIZE \"ENGINES\" NP RES RUNS BUILD JOBS [\"SCENARIOS\"]" >&2; exit 1; }
mode=$1 size=$2 engines=$3 np=$4 res=$5 runs=$6 build=$7 jobs=$8 scenarios=${9:-}
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root" || exit 3
command -v snakemake > /dev/null || { echo "campaign.sh: snakemake not installed (scripts/deps.sh campaign)" >&2; exit 7; }
[[ $jobs =~ ^[1-9][0-9]*$ ]] || { echo "campaign.sh: JOBS must be a positive integer, got '$jobs'" >&2; exit 1; }
# mtime, as make: a step is redone when one of its inputs (scenario file,
# deck, binaries, scripts) is newer than its outputs; --drop-metadata: no
# recorded checksums, which would make Snakemake skip a newer input with the
# content it last ran with (docs/campaign.md)
# (--config, --quiet and --rerun-triggers take lists: each ends at the next
# option, and the last option is a flag, so that targets can follow)
smk=(snakemake --snakefile workflow/Snakefile -j "$jobs"
     --config "size=$size" "engines=$engines" "np=$np" "res=$res" "runs=$runs" "build=$build" "scenarios=$scenarios"
              "from_cg=${FROM_CG:-0}"
     --quiet progress rules --rerun-triggers mtime --drop-metadata --rerun-incomplete --keep-going)
# Snakemake's scheduler chatter off; its errors and summaries stay
quiet() { grep --line-buffered -v -E '^(Select jobs to execute\.\.\.|Building DAG of jobs\.\.\.|Using shell: |Provided cores: |Rules claiming more threads will be scaled down\.|Complete log: )'; return 0; }
smk() { "${smk[@]}" "$@" 2>&1 | quiet; return "${PIPESTATUS[0]}"; }

case $mode in
  # only these rules: from the scores (figures: the results) that exist,
  # never a DEM run, a fit or an EKM run behind them
  table) smk --allowed-rules table calibration -- table calibration || exit $(( $? == 1 ? 4 : $? ))
         cat "$res/scores.md"; exit ;;
  figures) smk --allowed-rules figures -- figures || exit $(( $? == 1 ? 4 : $? )); exit ;;
  all) ;;
  *) echo "campaign.sh: unknown mode '$mode' (all, table, figures)" >&2; exit 1 ;;
esac
# the campaign's own stale temporaries, each named as it is removed:
# OUTPUT.tmp.PID whose process is gone (a step killed: ekmcompare's, the
# steps'; one whose process is alive is kept), OUTPUT.tmp (ekm's, the
# table's), and the DEM step's stamp temporary
"$root/scripts/campaign/stale_temps.sh" sweep "$res" || exit
stale() { # stale DIR DEPTH NAME: remove DIR's files named NAME, saying so
  [ -d "$1" ] || return 0
  find "$1" -maxdepth "$2" -type f -name "$3" -print0 | while IFS= read -r -d '' f; do
    rm -f -- "$f" && echo "campaign: removed stale temporary $f (left by an interrupted step)" >&2
  done
}
# (not while another campaign holds Snakemake's lock on this folder: those
# may be its files being written; Snakemake then refuses to start anyway)
if [ -n "$(ls -A "$root/.snakemake/locks" 2> /dev/null)" ]; then
  echo "campaign: another campaign holds the lock ($root/.snakemake/locks): temporaries left alone" >&2
else
  stale "$res" 4 '*.tmp'
  stale "$runs" 3 'campaign.stamp.tmp'
fi
if out=$("${smk[@]}" -n scores table calibration figures 2>&1); then
  case $out in
    *"Nothing to be done"*)
      echo "make campaign: everything is up to date ($res, SIZE=$size)"
      cat "$res/scores.md"; exit 0 ;;
  esac
else
  rc=$?   # the workflow did not parse: its status (2 bad scenario, 1 bad --config)
  echo "$out" | quiet >&2; exit $rc
fi
t0=$(date +%s); rc=0
smk scores || rc=4
# the table and the matrix from the scores that exist now, never a step
# behind them again (a failed step would keep the table from being made,
# and an old table show scores whose inputs are gone)
smk --allowed-rules table calibration -- table calibration || rc=4
cat "$res/scores.md"
[ -f "$res/calibration.md" ] && cat "$res/calibration.md"
smk figures || rc=4
echo "make campaign: SIZE=$size done in $(( $(date +%s) - t0 )) s: $res/scores.md, $res/figures/"
[ $rc -eq 0 ] || echo "make campaign: some steps FAILED (messages above; the table marks them missing)" >&2
exit $rc
