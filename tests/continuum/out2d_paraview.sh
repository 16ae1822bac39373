#!/usr/bin/env bash
# out2d_paraview.sh: ParaView's three XDMF readers open the sidecar of the
# 2D run output test_out2d writes (continuum/twod/out2d.h: 3 frames, 4 x 3
# cells) with every field equal to the HDF5 values and the mesh of the
# domain (tests/compare/paraview2d_check.py, the check of ekmcompare's 2D
# sidecars). Skipped (77) without pvpython (scripts/deps/paraview.txt).
# usage: out2d_paraview.sh TESTS_DIR OUTPUT_DIR
set -u
tests=$1 dir=$2
if ! command -v pvpython > /dev/null; then
  echo "skipped: pvpython not found (install python3-paraview: scripts/deps/paraview.txt)"
  exit 77
fi
dir=$(cd "$dir" && pwd) || exit 1 # absolute: the Xdmf3 readers resolve the HDF5 file from it
[ -f "$dir/run2d.h5" ] && [ -f "$dir/run2d.xdmf" ] || { echo "FAIL: no $dir/run2d.h5 + .xdmf (run test_out2d first)"; exit 1; }
pvpython --force-offscreen-rendering "$tests/compare/paraview2d_check.py" "$dir/run2d.xdmf" "$dir/run2d.h5" \
  > "$dir/paraview_log.txt" 2>&1
rc=$?
grep -v "^ \|^$" "$dir/paraview_log.txt" | head -40
exit $rc
