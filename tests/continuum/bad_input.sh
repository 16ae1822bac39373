#!/usr/bin/env bash
# Bad scenario files and command lines: each gives exactly one error line
# naming the file (or --set), the section and key, a non-zero exit code,
# and leaves no output file behind.
# usage: bad_input.sh EKM_BINARY SOURCE_DIR WORK_DIR
set -u
ekm=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
base="$src/scenarios/chute.ini"
failures=0 passed=0

# check NAME EXPECTED_EXIT 'PATTERN' ARGS... : run ekm, check exit code, one
# stderr line matching PATTERN, and no out.h5 / out.xdmf or temporary of
# them (out.h5.tmp.PID, out.xdmf.tmp.PID: common/atomic.h).
check() {
    local name=$1 want_rc=$2 pattern=$3; shift 3
    rm -f out.h5 out.h5.tmp* out.xdmf out.xdmf.tmp*
    "$ekm" "$@" 2> err.txt > /dev/null
    local rc=$? lines msg
    lines=$(wc -l < err.txt)
    msg=$(cat err.txt)
    if [ "$rc" -ne "$want_rc" ] || [ "$lines" -ne 1 ] || ! grep -qE -- "$pattern" err.txt \
       || [ -e out.h5 ] || [ -e out.xdmf ] || ls out.h5.tmp* out.xdmf.tmp* >/dev/null 2>&1; then
        echo "FAIL $name: exit $rc (want $want_rc), $lines lines: $msg"
        failures=$((failures + 1))
    else
        echo "ok   $name: $msg"
        passed=$((passed + 1))
    fi
}

grep -v '^eps0' "$base" > missing.ini
check "missing key" 2 "missing.ini: \[material\] eps0: missing" run missing.ini -o out.h5

sed 's/^\[material\]/[material]\nfoo = 1/' "$base" > unknown.ini
check "unknown key" 2 "unknown.ini:[0-9]+: \[material\] foo: unknown key" run unknown.ini -o out.h5

sed 's/^phi_cp .*/phi_cp = -0.64/' "$base" > negative.ini
check "negative phi_cp" 2 "negative.ini.*\[material\] phi_cp: expected" run negative.ini -o out.h5
check "--set range names the override" 2 "^ekm: --set material.phi_cp: \[material\] phi_cp: expected" run "$base" --set material.phi_cp=-1 -o out.h5
for key in surface_fill=1 solid_lag_tol=1e-2; do
    check "2D key $key in 1D" 2 "^ekm: --set numerics.${key%%=*}: \[numerics\] ${key%%=*}: needs \[domain\] width" \
        run "$base" --set "numerics.$key" -o out.h5
done
check "solid_lag_tol range" 2 "\[numerics\] solid_lag_tol: expected a number in \(0, 1\]" \
    run "$src/scenarios/thesis_filling_2d.ini" --set numerics.solid_lag_tol=0 -o out.h5

sed 's/^eps0 .*/eps0 = 5x0/' "$base" > malformed.ini
check "malformed number" 2 "malformed.ini:[0-9]+: \[material\] eps0: expected a number, got '5x0'" \
    run malformed.ini -o out.h5

check "unreadable file" 3 "nonexistent.ini: cannot open scenario file" run nonexistent.ini -o out.h5
mkdir -p dir.ini
mkdir -p outdir
check "output a directory" 3 "outdir/: cannot write the output: is a directory" run "$base" -o outdir/
check "output directory missing" 3 "nodir/out.h5: cannot write the output: directory nodir" run "$base" -o nodir/out.h5
check "not a regular file" 3 "dir.ini: cannot read scenario file: not a regular file" run dir.ini -o out.h5

cp "$base" unreadable.ini && chmod 000 unreadable.ini
if [ "$(id -u)" -ne 0 ]; then
    check "permission denied" 3 "unreadable.ini: cannot open" run unreadable.ini -o out.h5
fi

printf '[materal]\nrho_p = 1\n' | cat - "$base" > section.ini
check "unknown section" 2 "section.ini:[0-9]+: \[materal\]: unknown section" run section.ini -o out.h5

printf 'this is not ini\n' | cat "$base" - > syntax.ini
check "syntax error" 2 "syntax.ini:[0-9]+: expected" run syntax.ini -o out.h5

check "bad --set value" 2 "--set.*\[domain\] cells: expected an integer, got 'many'" \
    run "$base" -o out.h5 --set domain.cells=many

check "--set out of range" 2 "--set domain.length.*expected a length > 0" \
    run "$base" -o out.h5 --set domain.length=-1

check "bad stop" 2 "--set run.stop: \[run\] stop: expected 't_end' or 'steady', got 'never'" \
    run "$base" -o out.h5 --set run.stop=never
check "steady_tol out of range" 2 "--set run.steady_tol: \[run\] steady_tol: expected a rate > 0" \
    run "$base" -o out.h5 --set run.steady_tol=0
check "pressure on the bottom wall" 2 "--set bottom.pressure: \[bottom\] pressure: expected no pressure on the bottom wall" \
    run "$base" -o out.h5 --set bottom.pressure=100
check "pressure not positive" 2 "--set top.pressure: \[top\] pressure: expected a pressure > 0" \
    run "$src/scenarios/shear_cell.ini" -o out.h5 --set top.pressure=-5
check "pressure on a free top" 2 "--set top.pressure: \[top\] pressure: only allowed with type = wall" \
    run "$base" -o out.h5 --set top.pressure=100

# [top] shear_rate: the top wall's speed follows the gap (only with pressure)
shear_p="$src/scenarios/simple_shear_p.ini"
grep -v '^pressure *=' "$shear_p" > rate_no_p.ini
check "shear_rate without pressure" 2 "^ekm: rate_no_p.ini:$(grep -n '^shear_rate' rate_no_p.ini | cut -d: -f1): \[top\] shear_rate: only with \[top\] pressure" \
    run rate_no_p.ini -o out.h5
check "shear_rate with pressure none" 2 "^ekm: $shear_p:[0-9]+: \[top\] shear_rate: only with \[top\] pressure" \
    run "$shear_p" -o out.h5 --set top.pressure=none
sed 's/^shear_rate *=.*/shear_rate = -5/' "$shear_p" > rate_negative.ini
check "shear_rate negative" 2 "^ekm: rate_negative.ini:$(grep -n '^shear_rate' rate_negative.ini | cut -d: -f1): \[top\] shear_rate: expected a rate > 0 \[1/s\], got -5" \
    run rate_negative.ini -o out.h5
check "shear_rate zero" 2 "^ekm: --set top.shear_rate: \[top\] shear_rate: expected a rate > 0 \[1/s\], got 0" \
    run "$shear_p" -o out.h5 --set top.shear_rate=0
check "shear_rate on the bottom wall" 2 "^ekm: --set bottom.shear_rate: \[bottom\] shear_rate: expected no shear_rate on the bottom wall" \
    run "$shear_p" -o out.h5 --set bottom.shear_rate=10
check "shear_rate and top velocity" 2 "^ekm: --set top.velocity: \[top\] velocity: not with \[top\] shear_rate" \
    run "$shear_p" -o out.h5 --set top.velocity=0.1
grep -v '^velocity *= *-0.1' "$shear_p" > rate_outflow.ini
check "shear_rate over a bottom that is not a wall" 2 "^ekm: rate_outflow.ini:[0-9]+: \[top\] shear_rate: needs \[bottom\] type = wall .*, got outflow" \
    run rate_outflow.ini -o out.h5 --set bottom.type=outflow

check "unknown limiter" 2 "--set numerics.limiter: \[numerics\] limiter: unknown limiter 'foo' \(known: minmod vanleer superbee mc\)" \
    run "$base" -o out.h5 --set numerics.limiter=foo

check "inflow key on a wall" 2 "\[bottom\] phi: only allowed with type = inflow" \
    run "$base" -o out.h5 --set bottom.phi=0.3

check "solid without hypo" 2 "--set initial.solid.*\[initial\] solid: expected 0 unless \[hypo\] enabled = 1" \
    run "$base" -o out.h5 --set initial.solid=1

check "hypo yield_tol out of range" 2 "--set hypo.yield_tol.*\[hypo\] yield_tol: expected a number in \(0, 0.1\)" \
    run "$base" -o out.h5 --set hypo.enabled=1 --set hypo.yield_tol=0.5

check "hypo phi_fixed out of range" 2 "--set hypo.phi_fixed.*\[hypo\] phi_fixed: expected 0 \(the cell's phi\) or a number in \(phi_co, phi_cp\)" \
    run "$base" -o out.h5 --set hypo.enabled=1 --set hypo.phi_fixed=0.7

check "solid_relax_step out of range" 2 "--set numerics.solid_relax_step.*\[numerics\] solid_relax_step: expected a number in \(0, 1\]" \
    run "$base" -o out.h5 --set numerics.solid_relax_step=0

check "thermal_relax_step out of range" 2 "--set numerics.thermal_relax_step.*\[numerics\] thermal_relax_step: expected a number in \(0, 10\]" \
    run "$base" -o out.h5 --set numerics.thermal_relax_step=-1

check "normal_coupling unknown" 2 "--set numerics.normal_coupling.*\[numerics\] normal_coupling: expected 'implicit' or 'explicit', got 'semi'" \
    run "$base" -o out.h5 --set numerics.normal_coupling=semi

check "piston key on a wall" 2 "\[bottom\] w_return: only allowed with type = piston" \
    run "$base" -o out.h5 --set bottom.w_return=1e-6

check "piston without period" 2 "\[top\] period: missing \(required with type = piston\)" \
    run "$base" -o out.h5 --set top.type=piston --set top.w=-1e-6

check "missing argument" 1 "missing scenario file" run -o out.h5

check "unknown command" 1 "unknown command 'walk'" walk "$base"

# A run that cannot continue leaves no output either: a dt_min larger than
# any possible step stops it before the first step (run.c, the step limit).
check "solver failure" 4 "step limit .* below dt_min" run "$base" -o out.h5 --set initial.T=1e2 \
    --set numerics.phi_step_max=1e-9 --set numerics.dt_min=1e-3 --set numerics.dt_max=1

# The output may not replace the scenario file (exit 3, before any work),
# nor may its XDMF sidecar; the scenario stays as it was.
cp "$base" self.ini && cp "$base" self.xdmf
check "output is the scenario" 3 "self.ini: the output would overwrite the input self.ini" run self.ini -o self.ini
check "output is the scenario via ./" 3 "the output would overwrite the input" run self.ini -o ./self.ini
check "sidecar is the scenario" 3 "self.xdmf: the output would overwrite the input self.xdmf" \
    run self.xdmf -o self.h5
if cmp -s "$base" self.ini && cmp -s "$base" self.xdmf; then
    echo "ok   scenario files untouched"; passed=$((passed + 1))
else
    echo "FAIL scenario files were changed"; failures=$((failures + 1))
fi

# Stopped by a signal while writing: the temporaries are removed and the
# exit status is 128 + N (SIGTERM 15 -> 143, SIGINT 2 -> 130).  Job control
# on: a non-interactive shell starts background jobs with SIGINT ignored
# (which ekm then keeps ignoring, as a program should).
set -m
for sig in TERM INT; do
    rm -f out.h5 out.h5.tmp* out.xdmf out.xdmf.tmp*
    "$ekm" run "$base" -o out.h5 --quiet --set run.t_end=1e6 --set run.output_dt=100 2> err.txt &
    pid=$!
    for _ in $(seq 200); do ls out.h5.tmp.* >/dev/null 2>&1 && break; sleep 0.05; done
    had_tmp=no; ls out.h5.tmp.* >/dev/null 2>&1 && had_tmp=yes
    kill -s "$sig" "$pid"
    for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || break; sleep 0.05; done
    kill -0 "$pid" 2>/dev/null && kill -KILL "$pid"  # did not stop: fails below
    wait "$pid"; rc=$?
    want=$((128 + $(kill -l "$sig")))
    if [ "$had_tmp" = yes ] && [ "$rc" -eq "$want" ] && [ ! -e out.h5 ] && [ ! -e out.xdmf ] \
       && ! ls out.h5.tmp* out.xdmf.tmp* >/dev/null 2>&1; then
        echo "ok   SIG$sig while writing: exit $rc, no output, no temporary"; passed=$((passed + 1))
    else
        echo "FAIL SIG$sig while writing: temporary seen $had_tmp, exit $rc (want $want), left: $(ls out.* 2>/dev/null)"
        failures=$((failures + 1))
    fi
done
set +m

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
