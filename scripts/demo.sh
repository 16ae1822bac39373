#!/usr/bin/env bash
# make demo: run every shipped continuum scenario with ekm into
# runs/demo/continuum/ and print one summary line each.
# (The DEM and comparison parts of the smoke campaign join it in mk/ targets.)
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/runs/demo/continuum"
mkdir -p "$out"
echo "ekm: continuum scenarios -> runs/demo/continuum/"
for ini in "$root"/scenarios/*.ini; do
  name=$(basename "$ini" .ini)
  "$root/$build/continuum/ekm" run "$ini" -o "$out/$name.h5"
done
