#!/usr/bin/env bash
# promise.clear_errors.xdmf_output_name_{ekm,cg}: an output name the XDMF
# sidecar cannot name (a control character in its base name) is refused
# before any work: exit 1 (bad command line), one error line, no file
# written.  Issue 32: `ekm run case.ini -o $'a\nb.h5'` wrote a sidecar that
# referred to `a?b.h5`, a file that does not exist.
# A name with other non-ASCII UTF-8 (é) is still written, and its sidecar
# names it exactly.
# Usage: xdmf_output_name.sh ekm|cg EKM EKMCOMPARE SOURCE_DIR WORK_DIR
set -u
tool=$1 ekm=$2 ekmc=$3 src=$4 work=$5
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
run() { # run OUTPUT: the tool on a small case writing OUTPUT
    if [ "$tool" = ekm ]; then
        "$ekm" run "$src/scenarios/cooling.ini" -o "$1" --set run.t_end=1e-3 --quiet
    else
        "$ekmc" cg "$src/tests/compare/fixtures/chute_liggghts_atoms.dump.gz" --dt 1e-5 -o "$1"
    fi
}
fail=0
for bad in $'a\nb.h5' $'a\tb.h5' $'a\x7fb.h5' $'a\x1bb.h5'; do
    run "$bad" 2>err.txt
    rc=$?
    shown=$(printf '%q' "$bad")
    [ "$rc" -eq 1 ] || { echo "FAIL: -o $shown: exit $rc, expected 1"; fail=1; }
    [ "$(wc -l < err.txt)" -eq 1 ] || { echo "FAIL: -o $shown: stderr is not one line:"; cat err.txt; fail=1; }
    grep -q "XDMF sidecar" err.txt || { echo "FAIL: -o $shown: the error does not say why:"; cat err.txt; fail=1; }
    left=$(find . -mindepth 1 ! -name err.txt | head -3)
    [ -z "$left" ] || { echo "FAIL: -o $shown: left $left"; fail=1; }
    echo "-o $shown: exit $rc: $(head -1 err.txt)"
done
good=$'r\xc3\xa9sultat.h5'
run "$good" 2>err.txt || { echo "FAIL: -o $good: exit $?"; cat err.txt; fail=1; }
/usr/bin/python3 - "$good" <<'PY' || fail=1
import os, sys, xml.etree.ElementTree as ET
h5 = sys.argv[1]
xdmf = h5[:-3] + ".xdmf"
root = ET.parse(xdmf).getroot()
refs = {item.text.strip().split(":")[0] for item in root.iter("DataItem") if item.get("Format") == "HDF"}
if refs != {h5} or not os.path.exists(h5):
    sys.exit("FAIL: %s refers to %r, expected %r" % (xdmf, sorted(refs), h5))
print("%s refers to %s, which exists" % (xdmf, h5))
PY
exit $fail
