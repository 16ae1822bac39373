#!/usr/bin/env bash
# promise.no_partial_output.*: a run stopped by a signal leaves neither an
# output nor a temporary, and ends "killed by signal N" (status 128+N).
#   ekm: SIGTERM (timeout), SIGINT, SIGHUP sent to a run that never ends
#        (t_end = 1e300), once its temporary exists; SIGXFSZ from ulimit -f
#        on a run whose output outgrows the limit.
#   cg:  SIGTERM to ekmcompare cg reading a long series of dumps.
# Usage: signal.sh ekm|cg SIGNAL EKM EKMCOMPARE SOURCE_DIR WORK_DIR
set -u
tool=$1 sig=$2 ekm=$3 ekmcompare=$4 src=$5 work=$6
rm -rf "$work" && mkdir -p "$work/out" || exit 1
cd "$work" || exit 1
out=$work/out/o.h5
after=1 # s: the temporary exists long before
case $tool in
ekm)
    if [ "$sig" = XFSZ ]; then
        cmd=("$ekm" run "$src/scenarios/chute.ini" -o "$out" --set run.output_dt=0.01 --set run.t_end=5 --quiet)
    else
        cmd=("$ekm" run "$src/scenarios/cooling.ini" -o "$out" --set run.t_end=1e300 --set run.output_dt=1e299 --quiet)
    fi ;;
cg)
    # 400 snapshots: the fixture's two, repeated with increasing steps
    /usr/bin/python3 - "$src/tests/compare/fixtures/chute_liggghts_atoms.dump.gz" long.dump <<'PY' || exit 1
import gzip, sys
snaps = [s.split("\n", 1) for s in gzip.open(sys.argv[1], "rt").read().split("ITEM: TIMESTEP\n")[1:]]
first, every = int(snaps[0][0]), int(snaps[1][0]) - int(snaps[0][0])
with open(sys.argv[2], "w") as out:
    for k in range(400):
        out.write("ITEM: TIMESTEP\n%d\n%s" % (first + k * every, snaps[k % 2][1]))
PY
    cmd=("$ekmcompare" cg long.dump --dt 1e-5 --every 1 -o "$out")
    after=0.2 ;; # still reading (0.6 s to read them on a quiet machine)
esac
num=$(kill -l "$sig")
if [ "$sig" = XFSZ ]; then
    (ulimit -f 64; exec "${cmd[@]}") 2>err.txt
    rc=$?
else
    # timeout starts the command with default signal dispositions (a
    # background job of a script would have SIGINT ignored)
    timeout --preserve-status -s "$sig" "$after" "${cmd[@]}" 2>err.txt
    rc=$?
fi
left=$(ls -A "$work/out")
echo "$tool SIG$sig: exit $rc (want $((128 + num))); left: ${left:-nothing}; stderr: $(head -c 300 err.txt)"
fail=0
[ "$rc" -eq $((128 + num)) ] || { echo "FAIL: exit $rc, expected $((128 + num))"; fail=1; }
[ -z "$left" ] || { echo "FAIL: left behind: $left"; fail=1; }
exit $fail
