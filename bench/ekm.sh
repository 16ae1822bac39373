#!/usr/bin/env bash
# Solver rows of `make bench` (issues 2 and 12): cell-updates/s of shear_cell
# at 100-100000 cells and of filling, Newton iterations per step, and the
# thesis_filling wall time (docs/performance.md); writes $OUT/ekm.json.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$BUILD/bench/ekm_bench" "$root" "$OUT/ekm.json"
