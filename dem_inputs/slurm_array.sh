#!/usr/bin/env bash
# slurm_array.sh: the DEM part of the validation campaign on a cluster, as
# a Slurm job array: one array task per (scenario, engine) pair, each a
# `scripts/dem/run.sh` call with NP MPI ranks. When all tasks are done, run
# `make campaign SIZE=...` on any machine that sees the same checkout: it
# finds the finished DEM runs (same deck and variables: kept, not redone)
# and does the coarse-graining, EKM runs, scores and figures.
#
#   dem_inputs/slurm_array.sh --list [SIZE]      print the tasks (index: scenario engine)
#   sbatch --array=0-N dem_inputs/slurm_array.sh [SIZE]   (N = tasks - 1)
#
# Example (reference size, 4 ranks per run, 3 h per task):
#   n=$(dem_inputs/slurm_array.sh --list ref | wc -l)
#   sbatch --array=0-$((n - 1)) --ntasks=4 --time=03:00:00 dem_inputs/slurm_array.sh ref
#   # afterwards, on the login node or a workstation:
#   make campaign SIZE=ref
#
# The engines must be on PATH on the compute nodes (LIGGGHTS_EXE, LAMMPS_EXE
# override the binaries). NP = the task's --ntasks; with NP > 1 run.sh
# launches `mpirun -np NP`, which Open MPI binds to the Slurm allocation.
# Outputs: runs/<scenario>/<engine>-<size>/ as with `make dem`.
#SBATCH --job-name=ekmbench-dem
#SBATCH --output=runs/slurm-%A_%a.out
set -euo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/../scripts/campaign/lib.sh"   # root, campaign_scenarios, supported
list=0
if [ "${1:-}" = --list ]; then list=1; shift; fi
size=${1:-ref}
tasks=()
for s in $(campaign_scenarios); do
  for e in liggghts lammps; do
    if supported "$s" "$e"; then tasks+=("$s $e"); fi
  done
done
if [ $list -eq 1 ]; then
  for i in "${!tasks[@]}"; do echo "$i: ${tasks[$i]}"; done
  exit 0
fi
i=${SLURM_ARRAY_TASK_ID:?run through sbatch --array (see the header), or --list}
[ "$i" -lt ${#tasks[@]} ] || { echo "slurm_array.sh: task $i: only ${#tasks[@]} tasks (0-$(( ${#tasks[@]} - 1 )))" >&2; exit 2; }
set -- ${tasks[$i]}
np=${SLURM_NTASKS:-1}
echo "slurm_array.sh: task $i: $1 $2 $size with $np rank(s) on $(hostname)"
cd "$root"
rc=0
scripts/dem/run.sh -n "$np" "$1" "$2" "$size" || rc=$?
# 4 = finished but not steady: the data are usable (make campaign says so)
[ $rc -eq 0 ] || [ $rc -eq 4 ] || exit $rc
