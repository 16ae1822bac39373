#!/usr/bin/env bash
# `ekm scenario ... --json` (docs/resolved-scenario.md) from the command line:
# the JSON of the shipped scenarios checked with jq, stdout holding only the
# JSON, and the errors (one stderr line, exit code of docs/exit-codes.md,
# nothing on stdout).
# usage: scenario_cli.sh EKM_BINARY SOURCE_DIR WORK_DIR
set -u
ekm=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
ok() { echo "ok   $1"; passed=$((passed + 1)); }
bad() { echo "FAIL $1"; failures=$((failures + 1)); }

# json NAME 'JQ FILTER' ARGS...: ekm scenario ARGS exits 0, prints nothing on
# stderr, stdout is one JSON value and FILTER (jq -e) holds on it.
json() {
    local name=$1 filter=$2; shift 2
    "$ekm" scenario "$@" > out.json 2> err.txt
    local rc=$?
    if [ "$rc" -ne 0 ] || [ -s err.txt ]; then
        bad "$name: exit $rc: $(cat err.txt)"
    elif ! jq -e "$filter" out.json > /dev/null 2>&1; then
        bad "$name: '$filter' does not hold on: $(jq -c . out.json 2>&1 | head -c 2000)"
    else
        ok "$name"
    fi
}

# error NAME EXIT 'PATTERN' ARGS...: ekm ARGS exits EXIT with one stderr
# line matching PATTERN and nothing on stdout.
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

chute=$src/scenarios/chute.ini
shear=$src/scenarios/simple_shear.ini
line() { grep -n "^$2 *=" "$1" | head -1 | cut -d: -f1; }
version=$("$ekm" --version | sed 's/^ekm //')

json "chute lammps ref: header" \
    ".format == \"ekmbench-resolved-scenario\" and .format_version == 1 and .file == \"$chute\"
     and .scenario == \"chute\" and .engine == \"lammps\" and .size == \"ref\" and .code_version == \"$version\"" \
    "$chute" --engine lammps --size ref --json
json "chute lammps ref: three points" \
    '[.points[].tag] == ["theta22", "theta24", "theta26"]
     and [.points[].vars.theta] == ["22", "24", "26"]
     and [.points[].ekm_set] == [["gravity.angle=22"], ["gravity.angle=24"], ["gravity.angle=26"]]' \
    "$chute" --engine lammps --size ref --json
json "chute lammps ref: variants with their line" \
    ".keys[\"dem.lx\"] == {\"value\": \"20\", \"from\": \"$chute:$(line "$chute" ref.lx)\", \"as\": \"ref.lx\"}
     and .keys[\"dem.restitution_input\"] == {\"value\": \"0.724\",
         \"from\": \"$chute:$(line "$chute" lammps.restitution_input)\", \"as\": \"lammps.restitution_input\"}
     and .keys[\"compare.cg_options\"].value == \"--types 1 --stress c_sa --from 3.3\"
     and .keys[\"material.rho_p\"].from == \"$chute:$(line "$chute" rho_p)\"" \
    "$chute" --engine lammps --size ref --json
json "chute lammps ref: defaults" \
    '.keys["dem.thermo_every"] == {"value": "1000", "from": "default"}
     and .keys["numerics.cfl"] == {"value": "0.4", "from": "default"}
     and .keys["dem.t_end"].value == "5" and (.keys["dem.t_end"].from | test("chute.ini:[0-9]+$"))
     and (.keys["dem.seed"].from | test("chute.ini:[0-9]+$"))' \
    "$chute" --engine lammps --size ref --json
json "derived defaults: dem.t_end from [run] t_end, dem.pressure from [top] pressure" \
    '.keys["dem.t_end"] == {"value": "100", "from": "default"}
     and .keys["dem.pressure"] == {"value": "100", "from": "default"}' \
    "$src/scenarios/shear_cell.ini" --engine lammps --size ref --json
json "chute --set" \
    '.keys["dem.lx"] == {"value": "30", "from": "--set"} and .keys["gravity.angle"] == {"value": "30", "from": "--set"}
     and .points == [{"tag": "theta30", "vars": {"theta": "30"}, "ekm_set": ["gravity.angle=30"]},
                     {"tag": "theta31", "vars": {"theta": "31"}, "ekm_set": ["gravity.angle=31"]}]' \
    "$chute" --engine liggghts --size ref --set dem.lx=30 --set gravity.angle=30 --set "dem.ref.angles=30 31" --json
json "chute --point" '[.points[].tag] == ["theta24"]' "$chute" --engine lammps --size ref --point theta24 --json
json "chute smoke: one point" \
    '.points == [{"tag": "", "vars": {"theta": "24"}, "ekm_set": ["gravity.angle=24"]}]
     and .keys["dem.angles"] == {"value": "24", "from": "default"}' \
    "$chute" --engine lammps --size smoke --json
json "chute without engine and size" \
    '.engine == null and .size == null and (.keys["dem.lx"] | not) and (.points | length) == 1' "$chute" --json
json "simple_shear ref: 21 points" \
    '(.points | length) == 21 and .points[7] == {"tag": "phi0.53-rate10", "vars": {"phi": "0.53", "rate": "10"},
       "ekm_set": ["initial.phi=0.53", "top.velocity=0.1", "bottom.velocity=-0.1"]}
     and [.points[].tag] == [("0.45", "0.50", "0.53", "0.56", "0.58", "0.60", "0.62") as $p
       | ("5", "10", "20") as $r | "phi\($p)-rate\($r)"]' \
    "$shear" --engine lammps --size ref --json
shear_p=$src/scenarios/simple_shear_p.ini
json "simple_shear_p ref: pressures x rates, dump_every per point, EKM top wall at P moving at the rate" \
    '[.points[].tag] == [("10", "100", "1000") as $p | ("0.3", "1", "3", "10", "30") as $r | "p\($p)-rate\($r)"]
     and .points[5] == {"tag": "p100-rate0.3", "vars": {"pressure": "100", "rate": "0.3", "dump_every": "33333"},
       "ekm_set": ["top.pressure=100", "top.shear_rate=0.3", "bottom.velocity=-0.003"]}
     and [.points[0:5][].vars.dump_every] == ["33333", "10000", "3333", "1000", "333"]
     and .keys["dem.dump_strain"].value == "0.1" and .keys["dem.p_gain"].value == "0.25"
     and (.keys | has("dem.phis") | not)
     and .keys["top.shear_rate"].value == "10" and .keys["top.pressure"].value == "100"
     and (.keys | has("top.velocity") | not) and .keys["run.stop"].value == "steady"' \
    "$shear_p" --engine lammps --size ref --json
json "simple_shear_p --set dem.pressures: the plain key beats the variants" \
    '[.points[].tag] == ["p50-rate0.3", "p50-rate1", "p50-rate3", "p50-rate10", "p50-rate30"]' \
    "$shear_p" --engine lammps --size ref --set dem.pressures=50 --json
json "no [dem]: no dem keys, one point" \
    '([.keys | keys[] | select(startswith("dem.") or startswith("compare."))] | length) == 0
     and .points == [{"tag": "", "vars": {}, "ekm_set": []}]' \
    "$src/scenarios/cooling.ini" --engine lammps --size ref --json

# every shipped scenario, both engines and sizes
for f in "$src"/scenarios/*.ini; do
    for e in liggghts lammps; do
        for s in smoke ref; do
            json "$(basename "$f") $e $s" '.format == "ekmbench-resolved-scenario" and (.points | length) >= 1' \
                "$f" --engine "$e" --size "$s" --json
        done
    done
done

error "usage: no file" 1 "ekm scenario: missing scenario file" scenario --json
error "usage: no --json" 1 "ekm scenario: missing --json" scenario "$chute"
error "usage: unknown option" 1 "unexpected argument '--yaml'" scenario "$chute" --yaml
error "unreadable file" 3 "none.ini: cannot open scenario file" scenario none.ini --json
mkdir -p adir.ini
error "not a regular file" 3 "adir.ini: cannot read scenario file: not a regular file" scenario adir.ini --json
error "unknown engine" 2 "--engine spring: unknown engine" scenario "$chute" --engine spring --json
error "unknown size" 2 "--size huge: unknown size" scenario "$chute" --size huge --json
error "unknown point" 2 "--point theta23: unknown point \(the points are: theta22 theta24 theta26\)" \
    scenario "$chute" --size ref --point theta23 --json
sed 's/^ref\.lx .*/ref.lxx = 20/' "$chute" > unknown.ini
n=$(line unknown.ini ref.lxx)
error "unknown [dem] key" 2 "unknown.ini:$n: \[dem\] ref.lxx: unknown key" scenario unknown.ini --json
error "unknown [dem] key in ekm run" 2 "unknown.ini:$n: \[dem\] ref.lxx: unknown key" run unknown.ini -o out.h5
[ -e out.h5 ] && bad "ekm run left out.h5" || ok "ekm run left no output"
error "bad [compare] value" 2 "--set compare.ekm_time: \[compare\] ekm_time: expected one of last interp, got 'now'" \
    scenario "$chute" --set compare.ekm_time=now --json

sed '/^pressures *=/a phis = 0.5' "$shear_p" > both.ini
error "phis and pressures" 2 "both.ini:$(line both.ini phis): \[dem\] phis: a list of the phi x rate sweep, but \[dem\] pressures is one of the pressure x rate sweep" \
    scenario both.ini --json

sed "s/^description .*/description = caf$(printf '\xe9')/" "$src/scenarios/cooling.ini" > latin1.ini
n=$(line "$src/scenarios/cooling.ini" description)
error "not UTF-8" 2 "latin1.ini:$n: \[scenario\] description: expected UTF-8 text" scenario latin1.ini --json

# the closure style of the [material] keys: the EKM's, ekm_jam's (its own
# constants), mu_i's (its grain diameter a property, not a constant)
cl() { "$ekm" scenario "$@" --json | jq -c .closure; }
[ "$(cl "$src/scenarios/chute.ini")" = '{"name":"ekm_full","ekm_transport":true,"has_temperature":true,"slab_solver":"ekm","slab_takes":true,"slab_why":null,"params":[],"grain_properties":[]}' ] &&
  ok "resolved closure: ekm_full" || bad "resolved closure of chute.ini: $(cl "$src/scenarios/chute.ini")"
[ "$(cl "$src/tests/continuum/data/shear_cell_jam.ini")" = '{"name":"ekm_jam","ekm_transport":true,"has_temperature":true,"slab_solver":"ekm","slab_takes":true,"slab_why":null,"params":["phi_J","beta"],"grain_properties":[]}' ] &&
  ok "resolved closure: ekm_jam" || bad "resolved closure of shear_cell_jam.ini"
[ "$(cl "$src/scenarios/simple_shear_p.ini" --material "$src/scenarios/closures/mu_i.ini" --set model.closure=mu_i)" = '{"name":"mu_i","ekm_transport":false,"has_temperature":false,"slab_solver":"local","slab_takes":true,"slab_why":null,"params":["mu_s","mu_2","I_0","phi_max","phi_min"],"grain_properties":["d"]}' ] &&
  ok "resolved closure: mu_i" || bad "resolved closure of mu_i"
# mu_i's slab solver does not take a volume-controlled gap, and says why
cl "$src/scenarios/simple_shear.ini" --material "$src/scenarios/closures/mu_i.ini" --set model.closure=mu_i \
  --set numerics.gdot_min=1e-3 | jq -e '.slab_takes == false and (.slab_why | test("simple_shear.ini: \\[top\\]: a wall without pressure"))' > /dev/null &&
  ok "resolved closure: mu_i does not run a volume-controlled gap" || bad "slab_takes of mu_i on simple_shear.ini"

if "$ekm" --help | grep -q "ekm scenario FILE.ini"; then ok "ekm --help documents ekm scenario"; else bad "ekm --help"; fi

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
