#!/usr/bin/env bash
# `ekm homog` bad arguments: one stderr line naming the option or file and
# what was expected, the exit code of docs/exit-codes.md (1 bad command
# line, 2 bad value, 3 unreadable file), nothing on stdout.
# usage: homog_cli.sh EKM_BINARY SOURCE_DIR WORK_DIR
set -u
ekm=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
scen=$src/scenarios/simple_shear.ini

# error NAME EXIT 'PATTERN' ARGS...: ekm homog ARGS exits EXIT with one
# stderr line matching PATTERN and nothing on stdout.
error() {
    local name=$1 want=$2 pattern=$3
    shift 3
    "$ekm" homog "$@" > out.txt 2> err.txt
    local rc=$?
    if [ "$rc" -ne "$want" ] || [ "$(wc -l < err.txt)" -ne 1 ] || ! grep -qE -- "$pattern" err.txt ||
       [ -s out.txt ]; then
        echo "FAIL $name: exit $rc (want $want): $(cat err.txt) / stdout $(head -c 200 out.txt)"
        failures=$((failures + 1))
    else
        echo "ok   $name: $(cat err.txt)"
        passed=$((passed + 1))
    fi
}
error "no scenario" 1 "^ekm homog: missing scenario file" --phi 0.5:0.6:2 --rate 1 --json
error "no --phi" 1 "^ekm homog: missing --phi" "$scen" --rate 1 --json
error "no --rate" 1 "^ekm homog: missing --rate" "$scen" --phi 0.5:0.6:2 --json
error "no --json" 1 "^ekm homog: missing --json" "$scen" --phi 0.5:0.6:2 --rate 1
error "unknown option" 1 "^ekm homog: unexpected argument '--bogus'" "$scen" --bogus --phi 0.5:0.6:2 --rate 1 --json
error "two scenarios" 1 "^ekm homog: unexpected argument 'x.ini'" "$scen" x.ini --phi 0.5:0.6:2 --rate 1 --json
error "value missing" 1 "^ekm homog: --rate: missing its value" "$scen" --phi 0.5:0.6:2 --json --rate
error "phi not LO:HI:N" 2 "^ekm: --phi '0.5:0.6': expected LO:HI:N" "$scen" --phi 0.5:0.6 --rate 1 --json
error "phi not numbers" 2 "^ekm: --phi '0.5:x:3': expected LO:HI:N with numbers" "$scen" --phi 0.5:x:3 --rate 1 --json
error "phi N not integer" 2 "^ekm: --phi '0.5:0.6:2.5': N = 2.5: expected an integer" "$scen" --phi 0.5:0.6:2.5 --rate 1 --json
error "phi N zero" 2 "^ekm: --phi '0.5:0.6:0': N = 0" "$scen" --phi 0.5:0.6:0 --rate 1 --json
error "phi out of (0, 1)" 2 "^ekm: --phi '0:0.6:3': expected volume fractions 0 < LO <= HI < 1" "$scen" --phi 0:0.6:3 --rate 1 --json
error "phi LO > HI" 2 "^ekm: --phi '0.6:0.5:3': expected volume fractions 0 < LO <= HI < 1" "$scen" --phi 0.6:0.5:3 --rate 1 --json
error "phi N = 1, LO != HI" 2 "^ekm: --phi '0.5:0.6:1': N = 1 needs LO = HI" "$scen" --phi 0.5:0.6:1 --rate 1 --json
error "rate zero" 2 "^ekm: --rate '10,0': '0': expected a shear rate > 0" "$scen" --phi 0.5:0.6:2 --rate 10,0 --json
error "rate not a number" 2 "^ekm: --rate '10,,3': '': expected a shear rate > 0" "$scen" --phi 0.5:0.6:2 --rate 10,,3 --json
error "rate inf" 2 "^ekm: --rate 'inf': 'inf': expected a shear rate > 0" "$scen" --phi 0.5:0.6:2 --rate inf --json
error "too many points" 2 "^ekm: --phi N = 100000 times 11 rates: at most 1000000 points" "$scen" --phi 0.1:0.6:100000 --rate 1,2,3,4,5,6,7,8,9,10,11 --json
error "bad --set" 2 "^ekm: --set material.eps0: \[material\] eps0: expected a number, got 'x'" "$scen" --set material.eps0=x --phi 0.5:0.6:2 --rate 1 --json
error "missing scenario" 3 "^ekm: nonexistent.ini: cannot open scenario file" nonexistent.ini --phi 0.5:0.6:2 --rate 1 --json
error "missing material file" 3 "^ekm: nofit.ini: cannot open material file" "$scen" --material nofit.ini --phi 0.5:0.6:2 --rate 1 --json
echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
