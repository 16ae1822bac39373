#!/usr/bin/env bash
# scripts/campaign/ekm_step.sh EKM STOP OUT ARGS...: the EKM output OUT of
# one campaign point (workflow rules ekm and ekm_set); ARGS are the
# scenario file and its options (--material, --set).
#   STOP = steady  the scenario runs to its steady state ([run] stop):
#                  `ekm steady` (Newton, verified by the time stepper:
#                  docs/model/steady.md "Steady solver") and `ekm run` from the
#                  scenario's initial state; the Newton state is used when
#                  it agrees with the run's (`ekm agree`, continuum/point.h:
#                  the run ended steady, phi, vx, T, P and the gap within
#                  5e-2 of the run's maxima: the run stops at its own
#                  steady test, 1.1e-2 short of the fixed point on the
#                  chute at 24 degrees): a slab can have more than one
#                  steady state, and the one compared with the DEM is the
#                  one the initial state flows to.  Otherwise (Newton finds
#                  none, exit 6; does not take the scenario, exit 2; finds
#                  another one) that run's output is OUT: it ends steady or
#                  records that it did not (steady = 0, the table's
#                  "not steady").  The log says which.
#   otherwise      `ekm run`
# The exit code is the last program's (docs/exit-codes.md); a signal ends
# the step with 128+N, as the programs do.
set -uo pipefail
[ $# -ge 4 ] || { echo "ekm_step.sh: usage: ekm_step.sh EKM STOP OUT FILE.ini [OPTIONS...]" >&2; exit 1; }
ekm=$1 stop=$2 out=$3
shift 3
[ "$stop" = steady ] || exec "$ekm" run "$@" -o "$out" --quiet
tmp=$(mktemp -d "$(dirname "$out")/.ekm_step.XXXXXX") || exit 3
trap 'rm -rf "$tmp"' EXIT
for sig in INT TERM HUP; do
  trap "rm -rf \"\$tmp\"; trap - $sig EXIT; exit \$((128 + $(kill -l $sig)))" "$sig"
done
"$ekm" run "$@" -o "$tmp/run.h5" --quiet
rc=$?
[ $rc -eq 0 ] || [ $rc -eq 6 ] || exit $rc
"$ekm" steady "$@" -o "$out" --quiet
rc=$?
if [ $rc -eq 0 ]; then
  verdict=$("$ekm" agree "$out" "$tmp/run.h5" --tol 5e-2)
  arc=$?
  [ $arc -eq 0 ] || [ $arc -eq 6 ] || exit $arc
  if [ $arc -eq 0 ]; then
    echo "campaign: $out: ekm steady (Newton) $verdict with ekm run"
    exit 0
  fi
  echo "campaign: $out: ekm steady (Newton) found another steady state than ekm run ($verdict): the run's output is used"
elif [ $rc -eq 6 ] || [ $rc -eq 2 ]; then
  echo "campaign: $out: ekm steady found no steady state (exit $rc): the run's output is used"
else
  exit $rc
fi
rm -f "$out" "${out%.h5}.xdmf"
"$ekm" run "$@" -o "$out" --quiet
