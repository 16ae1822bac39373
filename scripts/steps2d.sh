#!/usr/bin/env bash
# scripts/steps2d.sh: how the 2D filling's results depend on the step
# size (docs/model/twod.md "The step's accuracy in 2D"); figures/steps2d.py
# tabulates them into results/ekm2d/step_study/.
#
#   f18_rN     thesis_filling_2d, 18 x 60 cells, flow regimes, with
#              [numerics] thermal_relax_step = N (the limit that sets
#              almost every step of this run: dt times the kinetic
#              pressure's relaxation rate at most N)
#   s18_rN     the same with the solid regime
#   s18_lN     the solid regime with [numerics] solid_lag_tol = N (the
#              solid cells' lag error per step, the limit that sets most
#              of the bed's steps; the scenario's 5e-2)
#   s9_dN      the 9 x 30 filling with the solid regime (the grid the
#              fully implicit solver ran), [numerics] dt_max = N (none:
#              the step's own limits)
#
# Runs go to RUNS (default runs/steps2d/, not committed); a run whose .h5
# exists is not run again, so the script resumes after an interruption.
# JOBS runs at a time (default 2), one core each. About 20 min of CPU in
# all (2026-12-06, this machine).
# usage: scripts/steps2d.sh [BUILD_DIR]     env: RUNS, JOBS
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
ekm="$root/$build/continuum/ekm"
runs=${RUNS:-$root/runs/steps2d}
jobs=${JOBS:-2}
[ -x "$ekm" ] || { echo "steps2d.sh: $ekm not built (make build)" >&2; exit 1; }
mkdir -p "$runs"

f=thesis_filling_2d
s9="--set hypo.enabled=1 --set domain.cells_x=9 --set domain.cells=30"
cases=(
  "f18_r1 $f --set numerics.thermal_relax_step=1"
  "f18_r0.5 $f --set numerics.thermal_relax_step=0.5"
  "f18_r0.2 $f --set numerics.thermal_relax_step=0.2"
  "f18_r0.05 $f --set numerics.thermal_relax_step=0.05"
  "f18_r0.02 $f --set numerics.thermal_relax_step=0.02"
  "s18_r0.5 $f --set hypo.enabled=1 --set numerics.thermal_relax_step=0.5"
  "s18_r0.05 $f --set hypo.enabled=1 --set numerics.thermal_relax_step=0.05"
  "s18_l1e-3 $f --set hypo.enabled=1 --set numerics.solid_lag_tol=1e-3"
  "s18_l1e-2 $f --set hypo.enabled=1 --set numerics.solid_lag_tol=1e-2"
  "s18_l5e-2 $f --set hypo.enabled=1 --set numerics.solid_lag_tol=5e-2"
  "s18_l0.2 $f --set hypo.enabled=1 --set numerics.solid_lag_tol=0.2"
  "s9_dnone $f $s9 --set numerics.thermal_relax_step=0.05"
  "s9_d1e-3 $f $s9 --set numerics.thermal_relax_step=0.05 --set numerics.dt_max=1e-3"
  "s9_d3e-4 $f $s9 --set numerics.thermal_relax_step=0.05 --set numerics.dt_max=3e-4"
  "s9_d1e-4 $f $s9 --set numerics.thermal_relax_step=0.05 --set numerics.dt_max=1e-4"
  "s9_d3e-5 $f $s9 --set numerics.thermal_relax_step=0.05 --set numerics.dt_max=3e-5"
)

# shellcheck source=scripts/lib/ekm_runs.sh
. "$root/scripts/lib/ekm_runs.sh"
ekm_runs steps2d
/usr/bin/python3 "$root/figures/steps2d.py" --runs "$runs" -o "$root/results/ekm2d/step_study"
