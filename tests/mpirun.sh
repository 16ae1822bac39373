#!/usr/bin/env bash
# mpirun.sh: run a command on N MPI ranks the way every test and CI job
# does (docs/build.md, "Running on N ranks"): OpenMPI's mpirun with
# --oversubscribe (more ranks than cores is fine for a test) and, when run
# as root (CI containers), the two variables OpenMPI requires to allow it.
# usage: tests/mpirun.sh N COMMAND [ARG ...]
# Exit: the command's status; 7 when mpirun is missing (openmpi-bin:
# scripts/deps.sh ekm2d); 1 on a bad N.
set -u
if [ $# -lt 2 ] || ! [[ $1 =~ ^[1-9][0-9]*$ ]]; then
  echo "mpirun.sh: usage: mpirun.sh N COMMAND [ARG ...] (N ranks, N >= 1)" >&2
  exit 1
fi
np=$1; shift
mpirun=${EKM_MPIRUN:-mpirun}
command -v "$mpirun" > /dev/null ||
  { echo "mpirun.sh: $mpirun not found (openmpi-bin: scripts/deps.sh ekm2d)" >&2; exit 7; }
if [ "$(id -u)" -eq 0 ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
fi
exec "$mpirun" --oversubscribe -np "$np" "$@"
