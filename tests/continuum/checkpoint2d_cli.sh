#!/usr/bin/env bash
# ekm run --checkpoint on a 2D scenario (continuum/twod/checkpoint2d.h,
# docs/model/twod.md "Checkpoints"): a small fast pile (thesis_sandpile_2d,
# 28 x 14 cells, w = -0.35 m/s, the solid regime on) run to 0.2 s at once
# (the stream lands at about 0.1 s);
#  - run to 0.15 s with a checkpoint after every frame, then the same
#    command to 0.2 s: every dataset of the output bitwise equal to the
#    run at once, the same step count, stats.resumed_at_t = 0.15;
#  - killed (SIGTERM) once a checkpoint exists: exit 143, no output and no
#    temporary left; the same command again finishes with the output of
#    the run at once, bitwise;
#  - a checkpoint written on 2 ranks goes on on 1: its frames copied
#    bitwise, the mass entered = the mass held (to 1e-12);
#  - refusals, one line each and nothing written: a checkpoint of another
#    scenario (exit 2, the key named), a file that is not HDF5 (exit 2), a
#    t_end before the checkpoint (exit 2), --checkpoint on a 1D scenario and
#    --checkpoint-every without --checkpoint or with a bad value (exit 1
#    usage), the checkpoint named as the output or the scenario (exit 3).
# usage: checkpoint2d_cli.sh EKM_BINARY SOURCE_DIR WORK_DIR MPIRUN_SH
# shellcheck disable=SC2015  # A && ok || bad: ok only echoes, it cannot fail
set -u
ekm=$1 src=$2 work=$3 mpirun=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0 passed=0
ok() { echo "ok   $1"; passed=$((passed + 1)); }
bad() { echo "FAIL $1"; failures=$((failures + 1)); }
py=/usr/bin/python3
scen="$src/scenarios/thesis_sandpile_2d.ini"
pile=(--set hypo.enabled=1 --set top.w=-0.35 --set domain.cells_x=28 --set domain.cells=14)

# same H5 H5 [FRAMES]: every dataset equal bitwise (FRAMES: only the first
# FRAMES frames of the fields and /t), and the same stats.steps unless FRAMES
same() {
    "$py" - "$@" <<'PY'
import sys, h5py, numpy as np
a, b = h5py.File(sys.argv[1], "r"), h5py.File(sys.argv[2], "r")
n = int(sys.argv[3]) if len(sys.argv) > 3 else None
bad = []
for k in a:
    if not isinstance(a[k], h5py.Dataset) or k not in b:
        continue
    x, y = np.asarray(a[k]), np.asarray(b[k])
    if n is not None and k not in ("x", "z"):
        x, y = x[:n], y[:n]
    if x.shape != y.shape or not np.array_equal(x, y):
        bad.append(k)
if n is None and a.attrs["stats.steps"] != b.attrs["stats.steps"]:
    bad.append("stats.steps %g %g" % (a.attrs["stats.steps"], b.attrs["stats.steps"]))
if bad:
    print("  differ:", bad)
sys.exit(1 if bad else 0)
PY
}

"$ekm" run "$scen" "${pile[@]}" --set run.t_end=0.2 -o once.h5 --quiet || bad "the run at once: exit $?"

# 1. stopped at a t_end, continued to a later one
"$ekm" run "$scen" "${pile[@]}" --set run.t_end=0.15 -o first.h5 --checkpoint ck.h5 --checkpoint-every 0 --quiet &&
    [ -s ck.h5 ] && ok "a run with --checkpoint leaves its checkpoint" || bad "no checkpoint after the run"
"$ekm" run "$scen" "${pile[@]}" --set run.t_end=0.2 -o cont.h5 --checkpoint ck.h5 2> cont.err > /dev/null ||
    bad "the continued run: exit $?: $(cat cont.err)"
grep -q "resumed from ck.h5 at t = 0.15 s" cont.err && ok "the continued run says where it resumed" ||
    bad "no resume line: $(cat cont.err)"
same once.h5 cont.h5 && ok "continued to a later t_end: bitwise the run at once" ||
    bad "continued run differs from the run at once"
"$py" -c "import h5py,sys; sys.exit(0 if abs(h5py.File('cont.h5')['/'].attrs['stats.resumed_at_t'] - 0.15) < 1e-12 else 1)" &&
    ok "stats.resumed_at_t = 0.15" || bad "stats.resumed_at_t missing or wrong"

# 2. killed, then the same command again
rm -f ck2.h5
"$ekm" run "$scen" "${pile[@]}" --set run.t_end=0.2 -o killed.h5 --checkpoint ck2.h5 --checkpoint-every 0 \
    --quiet &
pid=$!
for _ in $(seq 1 600); do [ -s ck2.h5 ] && break; sleep 0.02; done
sleep 0.3
kill -TERM "$pid" 2> /dev/null
wait "$pid"
code=$?
[ "$code" -eq 143 ] && [ ! -e killed.h5 ] && [ -z "$(ls ./*.tmp.* 2> /dev/null)" ] &&
    ok "killed: exit 143, no output, no temporary" || bad "killed: exit $code, $(ls)"
"$ekm" run "$scen" "${pile[@]}" --set run.t_end=0.2 -o killed.h5 --checkpoint ck2.h5 --quiet ||
    bad "the run again after the kill: exit $?"
same once.h5 killed.h5 && ok "killed and run again: bitwise the run at once" ||
    bad "the run again after the kill differs from the run at once"

# 3. a checkpoint of 2 ranks on 1
if bash "$mpirun" 2 "$ekm" run "$scen" "${pile[@]}" --set run.t_end=0.15 -o np2.h5 --checkpoint ck_np2.h5 \
    --checkpoint-every 0 --quiet > np2.txt 2>&1; then
    "$ekm" run "$scen" "${pile[@]}" --set run.t_end=0.2 -o np2on1.h5 --checkpoint ck_np2.h5 --quiet ||
        bad "2-rank checkpoint on 1 rank: exit $?"
    same np2.h5 np2on1.h5 4 && ok "a 2-rank checkpoint on 1 rank: its 4 frames copied bitwise" ||
        bad "the 2-rank checkpoint's frames differ"
    "$py" - np2on1.h5 <<'PY' && ok "... mass held = mass entered to 1e-12" || bad "mass balance after the rank change"
import sys, h5py
a = h5py.File(sys.argv[1], "r").attrs
m, i = a["stats.mass_final"], a["stats.mass_in"]
print("  mass %.15g kg/m, entered %.15g" % (m, i))
sys.exit(0 if abs(m - i) <= 1e-12 * i else 1)
PY
else
    bad "2 ranks with a checkpoint: $(cat np2.txt)"
fi

# 4. refusals
refuse() { # refuse WHAT CODE PATTERN COMMAND...: exit CODE, one stderr line matching PATTERN, no out.h5
    local what=$1 want=$2 pat=$3
    shift 3
    rm -f out.h5
    "$@" > r.out 2> r.err
    local code=$?
    if [ "$code" -eq "$want" ] && [ "$(wc -l < r.err)" -eq 1 ] && grep -q -- "$pat" r.err && [ ! -e out.h5 ]; then
        ok "$what: exit $want, one line"
    else
        bad "$what: exit $code (want $want): $(cat r.err)"
    fi
}
cp ck.h5 keep.h5
refuse "another scenario's checkpoint" 2 "top.w = -0.3" \
    "$ekm" run "$scen" "${pile[@]}" --set top.w=-0.3 --set run.t_end=0.2 -o out.h5 --checkpoint ck.h5 --quiet
cmp -s ck.h5 keep.h5 && ok "... the checkpoint left as it was" || bad "the refused checkpoint was changed"
echo "not hdf5" > junk.h5
refuse "a checkpoint that is not HDF5" 2 "junk.h5" \
    "$ekm" run "$scen" "${pile[@]}" --set run.t_end=0.2 -o out.h5 --checkpoint junk.h5 --quiet
refuse "t_end before the checkpoint" 2 "beyond this run's \[run\] t_end" \
    "$ekm" run "$scen" "${pile[@]}" --set run.t_end=0.1 -o out.h5 --checkpoint ck.h5 --quiet
refuse "--checkpoint on a 1D scenario" 1 "for 2D runs" \
    "$ekm" run "$src/scenarios/simple_shear.ini" -o out.h5 --checkpoint c1.h5
refuse "--checkpoint-every without --checkpoint" 1 "needs --checkpoint" \
    "$ekm" run "$scen" -o out.h5 --checkpoint-every 10
refuse "--checkpoint-every -1" 1 "expected a wall time" \
    "$ekm" run "$scen" -o out.h5 --checkpoint c.h5 --checkpoint-every -1
refuse "the checkpoint named as the output" 3 "would overwrite" \
    "$ekm" run "$scen" -o out.h5 --checkpoint out.h5
refuse "the checkpoint named as the scenario" 3 "would overwrite" \
    "$ekm" run "$scen" -o out.h5 --checkpoint "$scen"

echo "checkpoint2d_cli: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
