#!/usr/bin/env bash
# `ekm run|scenario FILE.ini --material FIT.ini`: the whole [material]
# section from FIT.ini (as `ekmcompare fit --ini` writes it), its keys'
# provenance FIT.ini:LINE, the output's material_file attribute, --set
# still applied after it; a bad FIT.ini: one stderr line naming
# file:line and key, the exit code of docs/exit-codes.md, no output.
# usage: material_cli.sh EKM_BINARY SOURCE_DIR WORK_DIR
set -u
ekm=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
ok() { echo "ok   $1"; passed=$((passed + 1)); }
bad() { echo "FAIL $1"; failures=$((failures + 1)); }
scen=$src/scenarios/cooling.ini

cat > FIT.ini <<'INI'
; [material] fitted by ekmcompare fit --rheology (a test file)
; chi2/dof = 1.02
[material]
rho_p   = 2400 ; start value (not fitted)
phi_co  = 0.58 ; fitted, SE 0.004
phi_cp  = 0.64
T0      = 1.25
eta0    = 4.1e-4 ; fitted, SE 2e-5
zeta0   = 1e-4
lambda0 = 3.4e-4
eps0    = 250
nu      = 1
A_h     = 200e6
B_h     = 200e6
alpha   = 0
INI

"$ekm" scenario "$scen" --material FIT.ini --json > out.json 2> err.txt
if [ $? -ne 0 ] || [ -s err.txt ]; then
    bad "ekm scenario --material: $(cat err.txt)"
elif jq -e '.keys["material.phi_co"] == {"value": "0.58", "from": "FIT.ini:5"} and
            .keys["material.eps0"] == {"value": "250", "from": "FIT.ini:11"} and
            ([.keys | to_entries[] | select(.key | startswith("material.")) | .value.from | startswith("FIT.ini:")]
             | length == 12 and all)' out.json > /dev/null; then
    ok "ekm scenario --material: every [material] key from FIT.ini:LINE"
else
    bad "ekm scenario --material: $(jq -c '.keys | with_entries(select(.key | startswith("material.")))' out.json)"
fi

"$ekm" scenario "$scen" --material FIT.ini --set material.eps0=300 --json > out.json 2> err.txt
if jq -e '.keys["material.eps0"] == {"value": "300", "from": "--set"}' out.json > /dev/null 2>&1; then
    ok "--set after --material"
else
    bad "--set after --material: $(cat err.txt) $(jq -c '.keys["material.eps0"]' out.json)"
fi

if "$ekm" run "$scen" --material FIT.ini -o out.h5 --quiet 2> err.txt &&
   h5dump -a material_file out.h5 | grep -q '"FIT.ini"' &&
   h5dump -a material.eta0 out.h5 | grep -q '0.00041' &&
   h5dump -a material.rho_p out.h5 | grep -q '2400'; then
    ok "ekm run --material: material_file and the values of FIT.ini in the output"
else
    bad "ekm run --material: $(cat err.txt)"
fi

# error NAME EXIT 'PATTERN' FIT: ekm run --material FIT exits EXIT with one
# stderr line matching PATTERN, nothing on stdout and no output file.
error() {
    local name=$1 want=$2 pattern=$3 fit=$4
    rm -f bad.h5
    "$ekm" run "$scen" --material "$fit" -o bad.h5 > out.txt 2> err.txt
    local rc=$?
    if [ "$rc" -ne "$want" ] || [ "$(wc -l < err.txt)" -ne 1 ] || ! grep -qE -- "$pattern" err.txt ||
       [ -s out.txt ] || [ -e bad.h5 ]; then
        bad "$name: exit $rc (want $want): $(cat err.txt) / stdout $(head -c 200 out.txt)"
    else
        ok "$name: $(cat err.txt)"
    fi
}
sed 's/^eta0 .*/eta0    = 4.1e-4x/' FIT.ini > number.ini
error "not a number" 2 "^ekm: number.ini:8: \[material\] eta0: expected a number, got '4.1e-4x'" number.ini
{ cat FIT.ini; printf '[run]\nt_end = 1\n'; } > section.ini
error "another section" 2 "^ekm: section.ini:17: \[run\] t_end: a material file holds only \[material\]" section.ini
grep -v '^T0' FIT.ini > missing.ini
error "missing key" 2 "^ekm: missing.ini: \[material\] T0: missing" missing.ini
sed 's/^phi_cp .*/phi_cp  = 0.5/' FIT.ini > range.ini
# phi_co is checked against phi_cp: the message blames phi_co, at its line
error "out of range" 2 "^ekm: range.ini:$(grep -n '^phi_co' range.ini | cut -d: -f1): \[material\] phi_co: expected a number in \(0, phi_cp = 0.5\)" range.ini
error "unreadable" 3 "^ekm: nonexistent.ini: cannot open material file" nonexistent.ini

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
