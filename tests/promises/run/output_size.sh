#!/usr/bin/env bash
# promise.no_crash.output_larger_than_memory_limit: an output is built in
# memory (common/h5.c), so a run whose frames would not fit in
# EKM_H5OUT_MAX_BYTES (here about 72 GB: 50002 frames x 20000 cells x 8
# fields and /z) is refused before it starts, exit 2, one line, nothing written.
# Before the check it started and would have exhausted the memory.
# usage: output_size.sh EKM SCENARIO WORKDIR
set -u
ekm=$1 scenario=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
timeout 30 "$ekm" run "$scenario" -o big.h5 --set domain.cells=20000 --set run.output_dt=1e-7 \
  --set run.t_end=0.005 2> err.txt
rc=$?
fail() { echo "FAIL: $*"; cat err.txt; exit 1; }
[ $rc -eq 2 ] || fail "exit $rc, expected 2"
[ "$(wc -l < err.txt)" -eq 1 ] || fail "expected one line"
grep -qF "[run] output_dt: the output would hold about 72.4 GB (50002 frames x 20000 cells x 8 fields and /z)" err.txt ||
  fail "message"
ls big.* > /dev/null 2>&1 && fail "output or temporary left: $(ls big.*)"
echo "ok: $(cat err.txt)"
