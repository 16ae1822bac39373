# shellcheck shell=bash disable=SC2154  # ekm, root, runs, jobs, cases: the sourcing script's
# scripts/lib/ekm_runs.sh: the resumable batch of `ekm run`s of the study
# scripts (scripts/thesis2d.sh, scripts/steps2d.sh); sourced, not run.
#
# ekm_runs TAG: runs every entry "NAME SCENARIO ARGS..." of the array
# `cases` as `$ekm run $root/scenarios/SCENARIO.ini ARGS -o
# $runs/NAME.h5` (its progress, a line a minute, and its summary appended
# to $runs/NAME.log: `tail $runs/*.log` says how far the batch is), $jobs at a time, one core
# each. A run whose .h5 exists is not run again (ekm writes it under a
# temporary name and renames it when complete), so a batch resumes after an
# interruption; a run cut short goes on from its checkpoint
# ($runs/NAME.ckpt.h5, written every 10 minutes of wall time by `ekm run
# --checkpoint`, removed when the run is complete), with the same steps. Each outcome is one stderr line "TAG: NAME ..."; returns 1
# when any run failed. An entry is split at blanks: a value with a blank
# in it (a list such as [top] inlet_x) goes into a scenario file, not into
# a --set here.

ekm_run_one() {
  local tag=$1 name=$2 scen=$3
  shift 3
  if [ -f "$runs/$name.h5" ]; then
    echo "$tag: $name: $runs/$name.h5 exists, not run again" >&2
    return 0
  fi
  "$ekm" run "$root/scenarios/$scen.ini" "$@" -o "$runs/$name.h5" --checkpoint "$runs/$name.ckpt.h5" \
    >> "$runs/$name.log" 2>&1 || { echo "$tag: $name failed (log: $runs/$name.log)" >&2; return 1; }
  rm -f "$runs/$name.ckpt.h5"
  echo "$tag: $name done" >&2
}

# (wait -n collects each run's status as it ends: waiting on a saved pid
# after `jobs` has reported its job done fails with "not a child of this
# shell", which made a batch whose runs all succeeded report a failure)
ekm_runs() {
  local tag=$1 c fail=0 running=0
  for c in "${cases[@]}"; do
    # shellcheck disable=SC2086
    ekm_run_one "$tag" $c &
    running=$((running + 1))
    if [ "$running" -ge "$jobs" ]; then
      wait -n || fail=1
      running=$((running - 1))
    fi
  done
  while [ "$running" -gt 0 ]; do
    wait -n || fail=1
    running=$((running - 1))
  done
  return "$fail"
}
