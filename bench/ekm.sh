#!/usr/bin/env bash
# Solver rows of `make bench` (issue 2): runs ekm_bench, writes $OUT/ekm.json.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$BUILD/bench/ekm_bench" "$root" "$OUT/ekm.json"
