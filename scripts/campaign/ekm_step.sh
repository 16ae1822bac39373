#!/usr/bin/env bash
# scripts/campaign/ekm_step.sh EKM STOP OUT ARGS...: the EKM output OUT of
# one campaign point (workflow rules ekm and ekm_set); ARGS are the
# scenario file and its options (--material, --set).
#   STOP = steady  the scenario runs to its steady state ([run] stop):
#                  `ekm steady` (Newton from the initial state, verified by
#                  the time stepper: docs/model.md "Steady solver"); when it
#                  finds no steady state there (exit 6) or does not take the
#                  scenario (exit 2, e.g. the solid regime), `ekm run`
#                  decides: it ends steady or records that it did not
#                  (steady = 0, the table's "not steady")
#   otherwise      `ekm run`
# The exit code is the last program's (docs/exit-codes.md); a signal ends
# the step with 128+N, as the programs do.
set -uo pipefail
[ $# -ge 4 ] || { echo "ekm_step.sh: usage: ekm_step.sh EKM STOP OUT FILE.ini [OPTIONS...]" >&2; exit 1; }
ekm=$1 stop=$2 out=$3
shift 3
if [ "$stop" = steady ]; then
  "$ekm" steady "$@" -o "$out" --quiet
  rc=$?
  [ $rc -eq 0 ] && exit 0
  if [ $rc -ne 6 ] && [ $rc -ne 2 ]; then
    exit $rc
  fi
  echo "campaign: $out: ekm steady found no steady state (exit $rc): time stepping decides (ekm run)" >&2
fi
exec "$ekm" run "$@" -o "$out" --quiet
