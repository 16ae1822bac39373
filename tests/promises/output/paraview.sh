#!/usr/bin/env bash
# promise.paraview.*: ParaView's three XDMF readers (XDMFReader,
# Xdmf3ReaderS, Xdmf3ReaderT) open the sidecar of an ekm output and of an
# ekmcompare cg output with every array, equal to the HDF5 values at two
# time steps, along ParaView's Z; Plot Over Line returns the cells' values
# (paraview_check.py).  Issue 13: the Xdmf3 readers showed no arrays
# ("Skipping unrecognized array type [None]": they cannot read HyperSlab
# items), the profile lay along Y, Plot Over Line was wrong at 616 of 1001
# samples, and cg outputs had no sidecar.  ekm_pwall: an ekm output whose
# pressure-held top wall moves the cells (issue 32): ParaView's cell
# centres of the first and last frame are that frame's row of /z.
# Skipped (77) without pvpython (Debian: python3-paraview,
# scripts/deps/paraview.txt).
# Usage: paraview.sh ekm|ekm_pwall|cg readers|plot_over_line EKM EKMCOMPARE SOURCE_DIR WORK_DIR
set -u
kind=$1 what=$2 ekm=$3 ekmcompare=$4 src=$5 work=$6
if ! command -v pvpython >/dev/null; then
    echo "skipped: pvpython not found (install python3-paraview: scripts/deps/paraview.txt)"
    exit 77
fi
rm -rf "$work" && mkdir -p "$work" || exit 1
work=$(cd "$work" && pwd) # absolute: the Xdmf3 readers resolve the HDF5 file from it
case $kind in
ekm) "$ekm" run "$src/scenarios/chute.ini" -o "$work/out.h5" --set run.t_end=0.5 --quiet || exit 1 ;;
ekm_pwall) # the gap closes from 42 to about 41.3 mm in 0.5 s
    "$ekm" run "$src/scenarios/shear_cell.ini" -o "$work/out.h5" --set run.t_end=0.5 --set run.output_dt=0.25 \
        --quiet || exit 1 ;;
cg) "$ekmcompare" cg "$src/tests/compare/fixtures/chute_liggghts_atoms.dump.gz" --dt 1e-5 --every 1 \
        -o "$work/out.h5" >/dev/null || exit 1 ;;
esac
[ -f "$work/out.xdmf" ] || { echo "FAIL: no sidecar $work/out.xdmf beside $work/out.h5"; exit 1; }
# reading and Plot Over Line need no display (no rendering)
pvpython --force-offscreen-rendering "$src/tests/promises/output/paraview_check.py" "$what" \
    "$work/out.xdmf" "$work/out.h5" >"$work/log.txt" 2>&1
rc=$?
grep -v "^ \|^$" "$work/log.txt" | head -40
exit $rc
