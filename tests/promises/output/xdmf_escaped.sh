#!/usr/bin/env bash
# promise.no_silent_values.xdmf_name_escaped: a scenario name with XML's
# special characters gives a well-formed XDMF sidecar whose collection
# carries the name exactly.  Issue 13: `[scenario] name = a<b>&"c` wrote it
# unescaped into the XML (not well-formed: no reader opens it).
# Usage: xdmf_escaped.sh EKM SOURCE_DIR WORK_DIR
set -u
ekm=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
name=$'a<b>&"c\' -- ]]> \xc3\xa9'
"$ekm" run "$src/scenarios/cooling.ini" -o o.h5 --set run.t_end=1e-3 --set "scenario.name=$name" --quiet || exit 1
fail=0
if command -v xmllint >/dev/null; then
    xmllint --noout o.xdmf || { echo "FAIL: xmllint: o.xdmf is not well-formed"; fail=1; }
fi
/usr/bin/python3 - "$name" <<'PY' || fail=1
import sys, xml.etree.ElementTree as ET
try:
    root = ET.parse("o.xdmf").getroot()
except ET.ParseError as e:
    sys.exit("FAIL: o.xdmf is not well-formed XML: %s" % e)
got = root.find("Domain/Grid").get("Name")
if got != sys.argv[1]:
    sys.exit("FAIL: collection name %r, expected %r" % (got, sys.argv[1]))
print("o.xdmf well-formed, collection name %r" % got)
PY
exit $fail
