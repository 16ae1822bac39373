#!/usr/bin/env bash
# status.sh JOBID: a Slurm job's state for Snakemake's --cluster-status
# (workflow/profiles/slurm/config.yaml): prints running, success or failed.
# sacct first (it knows finished jobs), squeue while sacct has no record yet.
set -uo pipefail
[ $# -eq 1 ] || { echo "status.sh: usage: status.sh JOBID" >&2; exit 1; }
id=$1
state=$(sacct -j "$id" -X -n -P -o State 2>/dev/null | head -n 1)
[ -n "$state" ] || state=$(squeue -h -j "$id" -o %T 2>/dev/null | head -n 1)
case ${state%% *} in
  COMPLETED) echo success ;;
  ""|PENDING|CONFIGURING|RUNNING|COMPLETING|SUSPENDED|REQUEUED|RESIZING|STAGE_OUT) echo running ;;
  *) echo failed ;;
esac
