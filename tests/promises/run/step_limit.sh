#!/usr/bin/env bash
# promise.no_hang.step_limit_below_dt_min: a filling whose inflow is at
# phi = 0.639 (0.001 below phi_cp) compresses its bottom cell until the
# compression step limit falls below dt_min.  The run used to go on with
# dt = 2e-19 s for ever (its ETA saying "2 s"); it must stop at once with
# exit 4 and one line saying when, which limit, which cell and its state,
# and leave no output.
# usage: step_limit.sh EKM SOURCE_DIR WORKDIR
set -u
ekm=$1 src=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
timeout 60 "$ekm" run "$src/scenarios/filling.ini" -o out.h5 --set top.phi=0.639 --set run.t_end=0.12 \
  2> err.txt
rc=$?
fail() { echo "FAIL: $*"; cat err.txt; exit 1; }
[ $rc -eq 124 ] && fail "still running after 60 s (the hang)"
[ $rc -eq 4 ] || fail "exit $rc, expected 4 (failed computation)"
msg=$(grep -v '^\s*t = ' err.txt | tr '\r' '\n' | grep 'dt_min' | tail -1)
[ -n "$msg" ] || fail "no message naming dt_min"
for want in "filling.ini: t = " "compression step limit" "below dt_min = 1e-12 s" "cell 0" "phi = 0.6399"; do
  case "$msg" in *"$want"*) ;; *) fail "message lacks '$want': $msg" ;; esac
done
ls out.h5* out.xdmf* > /dev/null 2>&1 && fail "output or temporary left: $(ls out.*)"
echo "ok: $msg"
