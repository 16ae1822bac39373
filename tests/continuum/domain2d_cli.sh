#!/usr/bin/env bash
# The 2D domain keys of the scenario reader ([domain] width, cells_x,
# periodic_x; docs/scenario-format.md) and the sand pile's sweep: resolved
# as documented (docs/resolved-scenario.md), absent from a 1D scenario,
# bad values one error line (exit 2); `ekm steady` on a scenario with
# cells_x > 1 refused with exit 7 (the 1D column only) and no output
# written, and so `ekm run` in an ekm built without the 2D solver (issue
# 14; `ekm --help` says which); "--" (PETSc options) on a 1D run or on ekm
# steady is a usage error (exit 1).
# usage: domain2d_cli.sh EKM_BINARY SOURCE_DIR WORK_DIR
set -u
ekm=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
ok() { echo "ok   $1"; passed=$((passed + 1)); }
bad() { echo "FAIL $1"; failures=$((failures + 1)); }

# json NAME 'JQ FILTER' ARGS...: ekm scenario ARGS exits 0, nothing on
# stderr, and FILTER (jq -e) holds on its stdout.
json() {
    local name=$1 filter=$2; shift 2
    "$ekm" scenario "$@" > out.json 2> err.txt
    local rc=$?
    if [ "$rc" -ne 0 ] || [ -s err.txt ]; then
        bad "$name: exit $rc: $(cat err.txt)"
    elif ! jq -e "$filter" out.json > /dev/null 2>&1; then
        bad "$name: '$filter' does not hold on: $(jq -c . out.json 2>&1 | head -c 1500)"
    else
        ok "$name"
    fi
}

# error NAME EXIT 'PATTERN' ARGS...: ekm ARGS exits EXIT with one stderr
# line matching PATTERN, nothing on stdout.
error() {
    local name=$1 want=$2 pattern=$3; shift 3
    "$ekm" "$@" > out.txt 2> err.txt
    local rc=$?
    if [ "$rc" -ne "$want" ] || [ "$(wc -l < err.txt)" -ne 1 ] || ! grep -qE -- "$pattern" err.txt || [ -s out.txt ]; then
        bad "$name: exit $rc (want $want): $(cat err.txt) / stdout $(head -c 200 out.txt)"
    else
        ok "$name: $(cat err.txt)"
    fi
}

pile=$src/scenarios/sandpile.ini
chute=$src/scenarios/chute.ini
line() { grep -n "^$2 *=" "$1" | head -1 | cut -d: -f1; }

json "sandpile: the 2D domain keys" \
    ".keys[\"domain.width\"] == {\"value\": \"0.26\", \"from\": \"$pile:$(line "$pile" width)\"}
     and .keys[\"domain.cells_x\"].value == \"65\" and .keys[\"domain.periodic_x\"].value == \"1\"" \
    "$pile" --json
json "sandpile ref: the two variants are the points" \
    '[.points[].tag] == ["source8", "source102"] and [.points[].vars.source_width] == ["8", "102"]
     and [.points[].ekm_set] == [
       ["top.inlet_width=0.016", "top.phi=0.09375", "top.w=-1", "top.t_stop=2.166666667",
        "bottom.plate_width=0.204", "run.t_end=4.2"],
       ["top.inlet_width=0.204", "top.phi=0.01470588235", "top.w=-1", "top.t_stop=2.166666667",
        "bottom.plate_width=0.204", "run.t_end=4.2"]]
     and .keys["dem.seeds"].value == "41"
     and .keys["dem.pile_mass"].as == "ref.pile_mass"' \
    "$pile" --engine liggghts --size ref --json
json "sandpile smoke: two seeds" '.keys["dem.seeds"].value == "2" and (.points | length) == 2' \
    "$pile" --engine lammps --size smoke --json
json "sandpile smoke: the sieve pours twice the hopper's mass rate over 42 d" \
    '[.points[].ekm_set[1]] == ["top.phi=0.08333333333", "top.phi=0.03174603175"]
     and [.points[].ekm_set[0]] == ["top.inlet_width=0.016", "top.inlet_width=0.084"]' \
    "$pile" --engine lammps --size smoke --json
# with a size, a key of the ekm_set missing is an error naming it
sed 's/^ref\.pile_mass .*//' "$pile" > nomass.ini
error "sandpile ref without pile_mass" 2 \
    "^ekm: nomass.ini: \[dem\] pile_mass: missing for size ref \(the sand-pile point's ekm_set" \
    scenario nomass.ini --engine lammps --size ref --json
# without a size the sizes' keys (pour_rate, pile_mass) are not resolved:
# only the sets whose keys are
json "sandpile: one width is a single point" \
    '.points == [{"tag": "", "vars": {"source_width": "8"},
                  "ekm_set": ["top.inlet_width=0.016", "bottom.plate_width=0.204", "run.t_end=4.2"]}]' \
    "$pile" --set dem.source_widths=8 --json
json "1D scenario: no 2D keys" \
    '[.keys | keys[] | select(. == "domain.width" or . == "domain.cells_x" or . == "domain.periodic_x")] == []' \
    "$chute" --engine lammps --size ref --json
json "1D scenario with a width: cells_x 1, periodic_x 0 by default" \
    '.keys["domain.width"] == {"value": "0.1", "from": "--set"}
     and .keys["domain.cells_x"] == {"value": "1", "from": "default"}
     and .keys["domain.periodic_x"] == {"value": "0", "from": "default"}' \
    "$chute" --set domain.width=0.1 --json

error "cells_x without width" 2 "--set domain.cells_x: \[domain\] cells_x: needs \[domain\] width" \
    scenario "$chute" --set domain.cells_x=4 --json
error "periodic_x without width" 2 "\[domain\] periodic_x: needs \[domain\] width" \
    scenario "$chute" --set domain.periodic_x=1 --json
error "width not > 0" 2 "\[domain\] width: expected a width > 0 \[m\], got 0" \
    scenario "$pile" --set domain.width=0 --json
error "cells_x not >= 1" 2 "\[domain\] cells_x: expected an integer in \[1, 1e7\], got 0" \
    scenario "$pile" --set domain.cells_x=0 --json
error "periodic_x not 0 or 1" 2 "\[domain\] periodic_x: expected 0 or 1, got 2" \
    scenario "$pile" --set domain.periodic_x=2 --json
error "source width not > 0" 2 "\[dem\] source_widths: expected source widths > 0 \[d\], got '-1'" \
    scenario "$pile" --set "dem.source_widths=8 -1" --json
error "sand pile and inclined flow keys together" 2 "one sweep only" \
    scenario "$pile" --set dem.angles=20 --json
# the boundaries of a 2D box: side walls ([left], [right]) and an inflow's
# inlet segment and opening time (docs/scenario-format.md)
box=$src/scenarios/thesis_filling_2d.ini
json "box: side walls resolved (no slip by default), inflow t_start 0, no inlet segment (the whole top)" \
    '.keys["left.type"] == {"value": "wall", "from": "default"} and .keys["right.slip_length"].value == "0"
     and .keys["top.t_start"].value == "0" and (.keys | has("top.inlet_width") | not)
     and (.keys | has("top.inlet_x") | not)' "$box" --json
json "box: an inlet segment, centred by default" \
    '.keys["top.inlet_width"] == {"value": "0.01", "from": "--set"} and .keys["top.inlet_x"].value == "0.035"' \
    "$box" --set top.inlet_width=0.01 --json
json "periodic box: no side-wall keys" '(.keys | has("left.type") | not) and (.keys | has("right.type") | not)' \
    "$box" --set domain.periodic_x=1 --json
json "1D inflow: no 2D inflow keys" '(.keys | has("top.t_start") | not) and (.keys | has("top.inlet_x") | not)' \
    "$src/scenarios/thesis_filling.ini" --json
error "inlet outside the top boundary" 2 \
    "--set top.inlet_x: \[top\] inlet_x: the inlet \[0.06, 0.08\] m is outside the top boundary \[0, 0.07\] m" \
    scenario "$box" --set top.inlet_x=0.07 --set top.inlet_width=0.02 --json
error "inlet narrower than a cell, between face centres" 2 \
    "\[top\] inlet_width: the inlet \[.*\] m holds no face centre of the 18 cells along x" \
    scenario "$box" --set top.inlet_x=0.0039 --set top.inlet_width=0.0001 --json
error "inlet_x without inlet_width" 2 "\[top\] inlet_x: needs \[top\] inlet_width" \
    scenario "$box" --set top.inlet_x=0.01 --json
# a floor that is a plate ([bottom] plate_x, plate_width: a wall end's
# faces beside it are open), centred by default, 2D only, on a wall that
# stays put
json "box: a plate, centred by default" \
    '.keys["bottom.plate_width"] == {"value": "0.03", "from": "--set"} and .keys["bottom.plate_x"].value == "0.035"' \
    "$box" --set bottom.plate_width=0.03 --json
json "box: no plate keys unless given" '(.keys | has("bottom.plate_width") | not) and (.keys | has("bottom.plate_x") | not)' \
    "$box" --json
error "plate outside the bottom boundary" 2 \
    "--set bottom.plate_x: \[bottom\] plate_x: the plate \[0.05, 0.09\] m is outside the bottom boundary \[0, 0.07\] m" \
    scenario "$box" --set bottom.plate_x=0.07 --set bottom.plate_width=0.04 --json
error "plate between face centres" 2 \
    "\[bottom\] plate_width: the plate \[.*\] m holds no face centre of the 18 cells along x" \
    scenario "$box" --set bottom.plate_x=0.0039 --set bottom.plate_width=0.0001 --json
error "plate_x without plate_width" 2 "\[bottom\] plate_x: needs \[bottom\] plate_width" \
    scenario "$box" --set bottom.plate_x=0.01 --json
error "plate_width 0" 2 "\[bottom\] plate_width: expected a width > 0 \[m\], got 0" \
    scenario "$box" --set bottom.plate_width=0 --json
error "plate on a 1D column" 2 "\[bottom\] plate_width: needs \[domain\] width \(a key of a 2D domain\)" \
    scenario "$src/scenarios/simple_shear.ini" --set bottom.plate_width=0.01 --json
error "plate on an inflow end" 2 "\[top\] plate_width" \
    scenario "$box" --set top.plate_width=0.01 --json
error "plate on a wall held at a pressure" 2 "\[top\] plate_width: a wall with openings must stay put" \
    scenario "$src/scenarios/shear_cell.ini" --set domain.width=0.01 --set domain.cells_x=4 \
    --set domain.periodic_x=1 --set top.plate_width=0.005 --json
# several inlet segments of one width: inlet_x a list of centres separated
# by blanks, each segment inside its end and holding a face centre, none
# overlapping another (touching is allowed), only with cells_x > 1
two=$src/scenarios/thesis_sandpile_2sources_2d.ini
json "two sources: inlet_x is the list as written, at its line" \
    ".keys[\"top.inlet_x\"] == {\"value\": \"0.045 0.095\", \"from\": \"$two:$(line "$two" inlet_x)\"}
     and .keys[\"top.inlet_width\"].value == \"0.01\"" "$two" --json
json "three inlets, touching ones allowed" '.keys["top.inlet_x"] == {"value": "0.01 0.02  0.035", "from": "--set"}' \
    "$box" --set "top.inlet_x=0.01 0.02  0.035" --set top.inlet_width=0.01 --json
sed 's/^inlet_x *=.*/inlet_x = 0.045 0.05 ; overlapping/' "$two" > overlap.ini
error "overlapping inlets, named at their file line" 2 \
    "^ekm: overlap.ini:$(line "$two" inlet_x): \[top\] inlet_x: the inlets \[0.04, 0.05\] m and \[0.045, 0.055\] m overlap \(expected centres at least inlet_width = 0.01 m apart\)$" \
    scenario overlap.ini --json
error "the second inlet outside the top boundary" 2 \
    "--set top.inlet_x: \[top\] inlet_x: the inlet \[0.131, 0.141\] m is outside the top boundary \[0, 0.14\] m" \
    scenario "$two" --set "top.inlet_x=0.045 0.136" --json
error "the second inlet holds no face centre" 2 \
    "\[top\] inlet_width: the inlet \[0.0099, 0.0101\] m holds no face centre of the 18 cells along x" \
    scenario "$box" --set "top.inlet_x=0.0019 0.01" --set top.inlet_width=0.0002 --json
error "inlet centres separated by commas" 2 \
    "--set top.inlet_x: \[top\] inlet_x: expected a number or numbers separated by blanks \(the inlet centres \[m\]\), got '0.045,0.095'" \
    scenario "$two" --set "top.inlet_x=0.045,0.095" --json
error "more than 8 inlets" 2 "\[top\] inlet_x: expected at most 8 inlet centres, got 9" \
    scenario "$two" --set "top.inlet_x=0.01 0.02 0.03 0.04 0.05 0.06 0.07 0.08 0.09" --json
error "several inlets in the 1D column" 2 \
    "\[top\] inlet_x: 2 inlets need a 2D domain \(\[domain\] cells_x > 1; the 1D column has one face per end\)" \
    scenario "$two" --set domain.cells_x=1 --json
error "t_start after t_stop" 2 "\[top\] t_start: expected a time >= 0 and before t_stop \[s\], got 3" \
    scenario "$box" --set top.t_start=3 --json
error "t_start in 1D" 2 "\[top\] t_start: needs \[domain\] width" \
    scenario "$src/scenarios/thesis_filling.ini" --set top.t_start=1 --json
error "side wall on a 1D column" 2 "\[left\] slip_length: needs \[domain\] width" \
    scenario "$chute" --set left.slip_length=0.001 --json
error "side wall slip_length < 0" 2 "\[right\] slip_length: expected a length >= 0 \[m\], got -1" \
    scenario "$box" --set right.slip_length=-1 --json
error "side wall not a wall" 2 "\[left\] type: expected wall \(a side of a 2D box\), got free" \
    scenario "$box" --set left.type=free --json
# periodic in x with walls on the same sides, in a file: named by file and line
sed 's/^periodic_x = 0 .*/periodic_x = 1/' "$box" > periodic_walls.ini
printf '[left]\ntype = wall\n' >> periodic_walls.ini
error "periodic in x with side walls" 2 \
    "^ekm: periodic_walls.ini:$(wc -l < periodic_walls.ini): \[left\] type: \[domain\] periodic_x = 1 has no side walls" \
    scenario periodic_walls.ini --json
grep -q '^periodic_x = 1' periodic_walls.ini && ok "periodic_walls.ini is periodic" || bad "sed did not set periodic_x"

where="sandpile.ini:$(line "$pile" cells_x): \[domain\] cells_x = 65"
if "$ekm" --help | grep -q "this ekm has the 2D solver"; then
    echo "skip ekm run on a 2D domain: this ekm has the 2D solver (its own tests run it)"
else
    msg="$where: the 2D solver is not built in this ekm \("
    error "ekm run refuses a 2D domain" 7 "^ekm: .*$msg" run "$pile" -o run.h5
    [ ! -e run.h5 ] && [ ! -e run.xdmf ] && ok "ekm run wrote nothing" || bad "ekm run left an output"
    error "a --set cells_x names --set" 7 "--set domain.cells_x: \[domain\] cells_x = 3: the 2D solver is not built" \
        run "$pile" --set domain.cells_x=3 -o run.h5
fi
error "ekm steady refuses a 2D domain" 7 "^ekm steady: .*$where: ekm steady solves the 1D column only" \
    steady "$pile" -o steady.h5
[ ! -e steady.h5 ] && ok "ekm steady wrote nothing" || bad "ekm steady left an output"
error "-- on a 1D run" 1 "^ekm run: '--' passes PETSc options to the 2D solver, but .*chute.ini is a 1D scenario" \
    run "$chute" -o chute.h5 -- -ts_monitor
[ ! -e chute.h5 ] && ok "-- on a 1D run wrote nothing" || bad "-- on a 1D run left an output"
error "-- on ekm steady" 1 "^ekm steady: unexpected argument '--'" steady "$pile" -o steady.h5 -- -ts_monitor

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
