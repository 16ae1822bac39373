#!/usr/bin/env bash
# `ekm steady`: the output (one frame of ekm run's format, steady = 1, the
# residual history, the XDMF sidecar), --from, and bad input: one stderr
# line naming the file or key and what was expected, the exit code of
# docs/exit-codes.md (2 bad input, 6 no steady state), no output file.
# usage: steady_cli.sh EKM_BINARY SOURCE_DIR WORK_DIR
set -u
ekm=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
S=$src/scenarios

check() { # NAME CONDITION-STATUS MESSAGE
    if [ "$2" -eq 0 ]; then
        echo "ok   $1"
        passed=$((passed + 1))
    else
        echo "FAIL $1: $3"
        failures=$((failures + 1))
    fi
}

# error NAME EXIT 'PATTERN' ARGS...: ekm steady ARGS exits EXIT with one
# stderr line matching PATTERN and writes no out.h5.
error() {
    local name=$1 want=$2 pattern=$3
    shift 3
    rm -f out.h5 out.xdmf
    "$ekm" steady "$@" -o out.h5 --quiet > out.txt 2> err.txt
    local rc=$?
    if [ "$rc" -ne "$want" ] || [ "$(wc -l < err.txt)" -ne 1 ] || ! grep -qE -- "$pattern" err.txt ||
       [ -e out.h5 ] || [ -e out.xdmf ]; then
        echo "FAIL $name: exit $rc (want $want): $(cat err.txt)"
        failures=$((failures + 1))
    else
        echo "ok   $name: $(cat err.txt)"
        passed=$((passed + 1))
    fi
}

# a solve: one frame, steady = 1, residual history, sidecar
"$ekm" steady "$S/simple_shear_p.ini" -o ssp.h5 > out.txt 2> err.txt
rc=$?
check "simple_shear_p solves" $rc "exit $rc: $(cat err.txt)"
[ -s ssp.xdmf ]
check "XDMF sidecar" $? "no ssp.xdmf"
grep -q "attempt 1 iteration   1  scaled residual" err.txt
check "progress on stderr" $? "$(head -3 err.txt)"
/usr/bin/python3 - ssp.h5 <<'EOF'
import sys, h5py
f = h5py.File(sys.argv[1], "r")
a = f.attrs
assert f["phi"].shape == (1, 20) and f["t"].shape == (1,), f["phi"].shape
# /z: the one frame's cell centres, at the solution's gap (ekm run's layout)
assert f["z"].shape == (1, 20) and abs(f["z"][0][-1] - 39 / 40 * a["gap_final"]) < 1e-15, f["z"][:]
assert a["steady"] == 1 and a["steady_solver"] == 1
n = int(a["steady.iterations"])
assert len(a["steady.residual"]) == n and len(a["steady.delta"]) == n and n >= 1
assert a["steady.residual_final"] < 1e-9 and a["steady.verify_change"] < 1e-9
assert abs(f["gap"][0] - a["gap_final"]) < 1e-15 and a["stats.wall_time_s"] > 0
# the verification: max-norm change of each field, >= 200 steps, counted in stats.steps
fields = [a["steady.verify_" + k] for k in ("phi", "vx", "T", "w", "gap")]
assert max(fields) == a["steady.verify_change"] and all(0 <= x < 1e-9 for x in fields), fields
assert a["steady.verify_steps"] >= 200 and a["steady.verify_time"] > 0
assert a["stats.steps"] == a["steady.warm_steps"] + a["steady.verify_steps"]
EOF
check "output layout and report attributes" $? "see above"
steps=$(/usr/bin/python3 -c "import h5py; print(int(h5py.File('ssp.h5').attrs['steady.verify_steps']))")
grep -qE "^simple_shear_p +steady .* verified over $steps steps \(max change [0-9.e+-]+\)" out.txt
check "summary line names the verification's steps" $? "$(cat out.txt)"

# the chute at 26 degrees: a dilute tail above the dense flow (phi < 1e-6
# in its top cells), every cell with material has u and T, empty ones none
"$ekm" steady "$S/chute.ini" --set gravity.angle=26 -o c26.h5 --quiet 2> err.txt
rc=$?
check "chute at 26 degrees solves" $rc "exit $rc: $(cat err.txt)"
/usr/bin/python3 - c26.h5 <<'EOF'
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1], "r")
phi, u, T = f["phi"][0], f["vx"][0], f["T"][0]
wet = phi >= 1e-9
assert np.sum((phi > 1e-9) & (phi < 1e-6)) >= 2, phi
assert np.all(T[wet] > 0) and np.all(u[wet] > 0) and np.all(T[~wet] == 0) and np.all(u[~wet] == 0)
EOF
check "chute at 26 degrees: the dilute tail, u and T where there is material" $? "see above"

# no steady state: nothing on stdout that looks like a solution, no output,
# the last stderr line the reason (before it only progress lines)
rm -f out.h5
"$ekm" steady "$S/chute.ini" --set bottom.slip_length=1e30 --set run.t_end=1 -o out.h5 > out.txt 2> err.txt
rc=$?
[ "$rc" -eq 6 ] && [ ! -s out.txt ] && [ ! -e out.h5 ] && tail -1 err.txt | grep -q ": no steady state: " &&
    [ "$(grep -vc "^ekm steady: chute: attempt [0-9]* iteration" err.txt)" -eq 1 ]
check "no steady state: exit 6, no summary line, no output" $? "exit $rc: $(cat out.txt) $(tail -2 err.txt)"

# --from an output on the same grid: converges at once
"$ekm" steady "$S/simple_shear_p.ini" --from ssp.h5 -o again.h5 --quiet 2> err.txt
rc=$?
check "--from a solution" $rc "exit $rc: $(cat err.txt)"
/usr/bin/python3 -c "
import h5py, numpy as np
a, b = h5py.File('ssp.h5'), h5py.File('again.h5')
assert b.attrs['steady.iterations'] <= 2, b.attrs['steady.iterations']
assert np.max(np.abs(a['phi'][0] - b['phi'][0])) < 1e-12
"
check "--from a solution: at most 2 iterations, same state" $? "see above"
# --from an output written before /z had a row per frame ([nz]: the first
# frame's centres; the gap of the last frame from /gap)
/usr/bin/python3 -c "
import h5py, shutil
shutil.copy('ssp.h5', 'old.h5')
with h5py.File('old.h5', 'r+') as f:
    z = f['z'][0]
    del f['z']
    f.create_dataset('z', data=z * 1.1).attrs['units'] = 'm'
"
"$ekm" steady "$S/simple_shear_p.ini" --from old.h5 -o again_old.h5 --quiet 2> err.txt
rc=$?
check "--from an output with one /z row" $rc "exit $rc: $(cat err.txt)"
/usr/bin/python3 -c "
import h5py, numpy as np
a, b = h5py.File('ssp.h5'), h5py.File('again_old.h5')
assert b.attrs['steady.iterations'] <= 2, b.attrs['steady.iterations']
assert np.max(np.abs(a['phi'][0] - b['phi'][0])) < 1e-12 and np.max(np.abs(a['z'][0] - b['z'][0])) < 1e-15
"
check "--from an output with one /z row: the gap of /gap, same state" $? "see above"

error "--from another grid" 2 "ssp\.h5: /z has 20 cells, the scenario 40 \(\[domain\] cells\)" \
    "$S/simple_shear_p.ini" --set domain.cells=40 --from ssp.h5
"$ekm" steady "$S/simple_shear.ini" -o ss.h5 --quiet 2> /dev/null
error "--from another length" 2 "ss\.h5: /z\[0\] = 0\.0005 m, the scenario's cell centre is 0\.00075 m" \
    "$S/simple_shear.ini" --set domain.length=0.03 --from ss.h5
error "--from a missing file" 3 "nothere\.h5" "$S/simple_shear.ini" --from nothere.h5
error "solid regime" 2 "filling\.ini: \[hypo\] enabled = 1: the solid regime's stress depends on its history" \
    "$S/filling.ini"
error "inflow" 2 "filling\.ini: \[top\] type = inflow: its mass changes with time" \
    "$S/filling.ini" --set hypo.enabled=0
error "tilting base" 2 "chute\.ini: \[gravity\] angle_rate = 0\.01: a tilting base has no steady state" \
    "$S/chute.ini" --set gravity.angle_rate=0.01
error "no steady state" 6 "^ekm steady: .*chute\.ini: no steady state: " \
    "$S/chute.ini" --set bottom.slip_length=1e30 --set run.t_end=1
error "bad key" 2 "bogus" "$S/chute.ini" --set run.bogus=1

echo "$passed passed, $failures failed"
[ "$failures" -eq 0 ]
