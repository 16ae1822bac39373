#!/usr/bin/env bash
# cg2d_paraview.sh: ParaView's three XDMF readers open the sidecar of an
# `ekmcompare cg --axes x,z` output (two windows) with every field and SE
# equal to the HDF5 values (paraview2d_check.py). Skipped (77) without
# pvpython (Debian: python3-paraview, scripts/deps/paraview.txt).
# usage: cg2d_paraview.sh EKMCOMPARE CG_SYNTH TESTS_DIR WORK_DIR
set -u
ekmc=$1 synth=$2 tests=$3 work=$4
if ! command -v pvpython > /dev/null; then
  echo "skipped: pvpython not found (install python3-paraview: scripts/deps/paraview.txt)"
  exit 77
fi
rm -rf "$work" && mkdir -p "$work" || exit 1
work=$(cd "$work" && pwd) # absolute: the Xdmf3 readers resolve the HDF5 file from it
"$synth" "$work/a.dump" text 800 4 || exit 1
"$ekmc" cg "$work/a.dump" --axes x,z --every 2 --quiet -o "$work/out.h5" || exit 1
pvpython --force-offscreen-rendering "$tests/paraview2d_check.py" "$work/out.xdmf" "$work/out.h5" \
  > "$work/log.txt" 2>&1
rc=$?
grep -v "^ \|^$" "$work/log.txt" | head -40
exit $rc
