#!/usr/bin/env bash
# scripts/thesis2d.sh: the thesis's 2D cases (docs/model/twod.md "The thesis's
# 2D cases") run by ekm and drawn by figures/filling2d.py and
# figures/pile2d.py into results/ekm2d/ (the committed reference results):
#
#   thesis_filling_2d/flow    18 x 60 cells to t = 4 s, flow regimes
#   thesis_filling_2d/solid   the same with the solid regime
#   thesis_sandpile_2d/narrow_28x14, narrow_56x28, narrow_112x56
#                             the 10 mm inlet, solid regime, 3 resolutions
#   thesis_sandpile_2d/narrow7_56x28, narrow7_*_at_1s, _at_2s
#                             the 10 mm inlet at 7x the speed (w = -0.35
#                             m/s): the wide inlet's mass flux; also on
#                             28 x 14 and 112 x 56 cells to t = 2 s
#   thesis_sandpile_2d/narrow7stop1_56x28_at_{1,1.25,2,3.5}s,
#   narrow7stop1_112x56_at_{1,1.25,2,2.5}s
#                             the fast narrow inlet closed at 1 s: the pile
#                             left to itself; 112 x 56 to 2.5 s
#   thesis_sandpile_2d/narrow7stop1norules_56x28_at_{1,2,3.5}s
#                             the same without the surface rules that the
#                             pile scenarios set (surface_fill, phi_vacuum
#                             0.05: docs/model/twod.md "Surface cells in 2D")
#   thesis_sandpile_2d/narrow7full_56x28_at_1s, _at_2s
#                             the fast narrow pile with [model] variant =
#                             full (normal viscosity 4/3 eta + zeta)
#   thesis_sandpile_2d/wide_56x28
#                             a 70 mm inlet ("sieve"), 7x the narrow mass flux
#   thesis_sandpile_2d/2sources7_56x28, 2sources7_*_at_1s, _at_2s
#                             two 10 mm inlets at x = 0.045 and 0.095 m
#                             (thesis Fig. 4.20), each as the fast narrow
#                             one (w = -0.35 m/s); also on 28 x 14 cells to
#                             t = 2 s; figures with --extrema
#
# Runs go to RUNS (default runs/thesis2d/, not committed); a run whose .h5
# exists is not run again (delete it to redo), so the script resumes after
# an interruption, and a run cut short goes on from its checkpoint
# (NAME.ckpt.h5 beside it: scripts/lib/ekm_runs.sh). FIGURES_ONLY=1: no runs, the figures and numbers of the
# runs made so far (the others' figures are left as they are). One core per run, JOBS runs at a time (default 2). The
# 112 x 56 piles take 33-50 min each with the surface rules, the
# vapour-cell rule and the kept LU (2026-12-07, two at a time on a 2-core
# machine shared with a CI run: 1965, 2315 and 3019 s), the rest a few
# minutes each; each run's log
# carries its progress line once a minute (ETA included).
# usage: scripts/thesis2d.sh [BUILD_DIR]     env: RUNS, JOBS, FIGURES_ONLY
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
ekm="$root/$build/continuum/ekm"
runs=${RUNS:-$root/runs/thesis2d}
res="$root/results/ekm2d"
jobs=${JOBS:-2}
[ -x "$ekm" ] || { echo "thesis2d.sh: $ekm not built (make build)" >&2; exit 1; }
mkdir -p "$runs" "$res"

# name scenario settings...: one run (the long 112 x 56 runs first, the
# fast narrow pile's first: it completes the 3-resolution comparison)
cases=(
  "pile_narrow7_112x56 thesis_sandpile_2d --set hypo.enabled=1 --set top.w=-0.35 --set domain.cells_x=112 --set domain.cells=56 --set run.t_end=2"
  "pile_narrow7stop1_112x56 thesis_sandpile_2d --set hypo.enabled=1 --set top.w=-0.35 --set top.t_stop=1.0 --set run.t_end=2.5 --set domain.cells_x=112 --set domain.cells=56"
  "pile_narrow_112x56 thesis_sandpile_2d --set hypo.enabled=1 --set domain.cells_x=112 --set domain.cells=56"
  "filling_flow thesis_filling_2d"
  "filling_solid thesis_filling_2d --set hypo.enabled=1"
  "pile_narrow_28x14 thesis_sandpile_2d --set hypo.enabled=1 --set domain.cells_x=28 --set domain.cells=14"
  "pile_narrow_56x28 thesis_sandpile_2d --set hypo.enabled=1"
  "pile_narrow7_28x14 thesis_sandpile_2d --set hypo.enabled=1 --set top.w=-0.35 --set domain.cells_x=28 --set domain.cells=14 --set run.t_end=2"
  "pile_narrow7_56x28 thesis_sandpile_2d --set hypo.enabled=1 --set top.w=-0.35"
  "pile_narrow7full_56x28 thesis_sandpile_2d --set hypo.enabled=1 --set top.w=-0.35 --set model.variant=full --set run.t_end=2"
  "pile_wide_56x28 thesis_sandpile_2d --set hypo.enabled=1 --set top.inlet_width=0.07"
  "pile_2sources7_28x14 thesis_sandpile_2sources_2d --set hypo.enabled=1 --set top.w=-0.35 --set domain.cells_x=28 --set domain.cells=14 --set run.t_end=2"
  "pile_2sources7_56x28 thesis_sandpile_2sources_2d --set hypo.enabled=1 --set top.w=-0.35"
  "pile_narrow7stop1_56x28 thesis_sandpile_2d --set hypo.enabled=1 --set top.w=-0.35 --set top.t_stop=1.0 --set run.t_end=3.5"
  "pile_narrow7stop1norules_56x28 thesis_sandpile_2d --set hypo.enabled=1 --set top.w=-0.35 --set top.t_stop=1.0 --set run.t_end=3.5 --set numerics.surface_fill=0 --set numerics.phi_vacuum=0"
)

# shellcheck source=scripts/lib/ekm_runs.sh
. "$root/scripts/lib/ekm_runs.sh"
[ "${FIGURES_ONLY:-0}" = 1 ] || ekm_runs thesis2d

py=/usr/bin/python3
# draw SCRIPT RUN.h5 OUTDIR [ARGS...]: one figure script on one run; with
# FIGURES_ONLY=1 a run not made yet is skipped with a line
draw() {
  if [ ! -f "$2" ] && [ "${FIGURES_ONLY:-0}" = 1 ]; then
    echo "thesis2d: $2 not made yet: its figures are left as they are" >&2
    return 0
  fi
  $py -B "$@" >&2
}
for k in flow solid; do
  draw "$root/figures/filling2d.py" "$runs/filling_$k.h5" "$res/thesis_filling_2d/$k" >&2
done
for k in narrow_28x14 narrow_56x28 narrow_112x56 narrow7_56x28 wide_56x28; do
  draw "$root/figures/pile2d.py" "$runs/pile_$k.h5" "$res/thesis_sandpile_2d/$k" >&2
done
# the piles of the faster inflows stand before the layer reaches the side
# walls (at 3.5 s the plate is covered): their numbers at 1 and 2 s (the
# fast narrow inlet at 3 resolutions, run to 2 s on 28 x 14 and 112 x 56)
for k in narrow7_28x14 narrow7_56x28 narrow7_112x56 narrow7full_56x28 wide_56x28; do
  for bt in 1 2; do
    draw "$root/figures/pile2d.py" "$runs/pile_$k.h5" "$res/thesis_sandpile_2d/${k}_at_${bt}s" \
      --times 0.5,1,1.5,2 --base-time "$bt" >&2
  done
done
# two sources (thesis Fig. 4.20): the inlets and the base profile's maxima
# and minima marked; the box is full by 3.5 s (the two inlets pour twice
# the fast narrow inlet's mass), so also at 1 and 2 s
draw "$root/figures/pile2d.py" "$runs/pile_2sources7_56x28.h5" "$res/thesis_sandpile_2d/2sources7_56x28" \
  --extrema >&2
for k in 2sources7_28x14 2sources7_56x28; do
  for bt in 1 2; do
    draw "$root/figures/pile2d.py" "$runs/pile_$k.h5" "$res/thesis_sandpile_2d/${k}_at_${bt}s" \
      --times 0.5,1,1.5,2 --base-time "$bt" --extrema >&2
  done
done
# the pile at rest: the fast narrow inlet closed at 1 s, the pile left to
# itself until 3.5 s (docs/model/twod.md "thesis_sandpile_2d")
for bt in 1 1.25 2 3.5; do
  draw "$root/figures/pile2d.py" "$runs/pile_narrow7stop1_56x28.h5" \
    "$res/thesis_sandpile_2d/narrow7stop1_56x28_at_${bt}s" --times 0.5,1,1.5,2,3.5 --base-time "$bt" >&2
done
for bt in 1 1.25 2 2.5; do
  draw "$root/figures/pile2d.py" "$runs/pile_narrow7stop1_112x56.h5" \
    "$res/thesis_sandpile_2d/narrow7stop1_112x56_at_${bt}s" --times 0.5,1,1.5,2,2.5 --base-time "$bt" >&2
done
# the same pile without the surface rules (docs/model/twod.md "Surface cells in
# 2D"): it slumps
for bt in 1 2 3.5; do
  draw "$root/figures/pile2d.py" "$runs/pile_narrow7stop1norules_56x28.h5" \
    "$res/thesis_sandpile_2d/narrow7stop1norules_56x28_at_${bt}s" --times 0.5,1,1.5,2,3.5 --base-time "$bt" >&2
done
# the base rows' phi and P of every pile at its base times (the thesis's
# claim: P follows phi there)
$py -B - "$runs" "$res/thesis_sandpile_2d/base_rows.json" <<'PY'
import json, os, sys
import h5py
runs, out = sys.argv[1], sys.argv[2]
# a partial batch (FIGURES_ONLY) keeps the rows of the runs not made here
old = {}
if os.path.exists(out):
    with open(out) as fh:
        old = json.load(fh).get("rows", {})
rows = {}
for name in ("narrow_56x28", "narrow_112x56", "narrow7_28x14", "narrow7_56x28", "narrow7_112x56", "narrow7full_56x28",
             "wide_56x28", "2sources7_28x14", "2sources7_56x28", "narrow7stop1_56x28",
             "narrow7stop1_112x56", "narrow7stop1norules_56x28"):
    path = os.path.join(runs, "pile_%s.h5" % name)
    if not os.path.exists(path):   # a partial batch (FIGURES_ONLY): the rows it had
        rows.update({k: r for k, r in old.items() if k.startswith(name + "_at_")})
        continue
    with h5py.File(path, "r") as f:
        t = list(f["t"][:])
        for bt in (1.0, 2.0, 3.5):
            if bt > t[-1] + 1e-9:
                continue
            k = min(range(len(t)), key=lambda i: abs(t[i] - bt))
            rows["%s_at_%gs" % (name, bt)] = {
                "time": {"value": float(t[k]), "units": "s"},
                "x": {"value": [float(v) for v in f["x"][:]], "units": "m"},
                "phi": {"value": [float(v) for v in f["phi"][k, 0, :]], "units": "1"},
                "P": {"value": [float(v) for v in f["P"][k, 0, :]], "units": "Pa"}}
tmp = out + ".tmp"
with open(tmp, "w") as fh:
    json.dump({"program": "scripts/thesis2d.sh", "definitions": {
        "rows": "phi and P of the bottom row of cells (cell centres x) at the frame nearest to each time"},
        "rows": rows}, fh, indent=1)
os.replace(tmp, out)
PY
# one table of every pile's numbers at its base time (pile2d.json), the
# numbers docs/model/twod.md "The thesis's 2D cases" quotes
$py -B "$root/figures/pile2d_table.py" "$res/thesis_sandpile_2d" "$res/thesis_sandpile_2d/summary.md" \
  --title "thesis_sandpile_2d: every pile at its base time" \
  --about "Written by scripts/thesis2d.sh from each folder's pile2d.json (figures/pile2d.py: the definitions); the code version of each run in its row."
echo "thesis2d: figures and numbers in $res" >&2
