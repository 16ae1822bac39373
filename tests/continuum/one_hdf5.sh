#!/usr/bin/env bash
# one_hdf5.sh: every program given links exactly one HDF5 library, the
# build's (docs/build.md, "Which HDF5, and why": the OpenMPI HDF5 with the
# 2D solver, since PETSc links it, else the serial one), never two.
# usage: one_hdf5.sh openmpi|serial BINARY...
set -u
want=$1; shift
failures=0
for bin in "$@"; do
  libs=$(ldd "$bin" | awk '$1 ~ /^libhdf5(_openmpi|_serial)?\.so/ {print $3}' | sort -u)
  n=$(printf '%s\n' "$libs" | grep -c .)
  case "$want" in
    openmpi) ok_lib=$(printf '%s\n' "$libs" | grep -c "libhdf5_openmpi") ;;
    serial) ok_lib=$(printf '%s\n' "$libs" | grep -vc "libhdf5_openmpi") ;;
    *) echo "one_hdf5.sh: expected openmpi or serial, got '$want'"; exit 2 ;;
  esac
  if [ "$n" -ne 1 ] || [ "$ok_lib" -ne 1 ]; then
    echo "FAIL $bin: HDF5 libraries: ${libs:-none} (expected one, the $want HDF5)"
    failures=$((failures + 1))
  else
    echo "ok   $bin: $libs"
  fi
done
[ "$failures" -eq 0 ]
