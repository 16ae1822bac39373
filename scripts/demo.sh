#!/usr/bin/env bash
# make demo: the smoke version of everything, on a fresh machine in a few
# minutes: (1) every shipped continuum scenario through ekm (one summary
# line each, into runs/demo/continuum/), then (2) the smoke validation
# campaign (make campaign SIZE=smoke: DEM in both engines, coarse-graining,
# EKM, scores) ending with the score table and the figures in
# results/smoke/; then (3) a one-screen summary (scripts/campaign/
# demo_summary.py: where the results are, what to open first, headline
# numbers from results/smoke/scores.json), which fails the demo when the
# campaign left no readable score table.
# usage: scripts/demo.sh BUILD_DIR   (called by make demo after deps and build)
set -euo pipefail
build=${1:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/runs/demo/continuum"
mkdir -p "$out"
echo "== 1. ekm: every continuum scenario -> runs/demo/continuum/"
for ini in "$root"/scenarios/*.ini; do
  name=$(basename "$ini" .ini)
  nx=$("$root/$build/scenario/ekmscenario" "$ini" --json | jq -r '.keys["domain.cells_x"].value // "1"')
  if [ "$nx" != 1 ]; then
    if ! "$root/$build/continuum/ekm" --help | grep -q "this ekm has the 2D solver"; then
      echo "$name: 2D: this ekm is built without the 2D solver (docs/build.md), skipped"; continue
    fi
    case "$name" in
      thesis_filling_2d)
        # the box filling on 9 x 30 cells (half the thesis's grid) to its
        # end, t = 4 s, on 2 ranks (about a minute; the thesis's 18 x 60:
        # docs/model/twod.md "The thesis's 2D cases")
        bash "$root/tests/mpirun.sh" 2 "$root/$build/continuum/ekm" run "$ini" --set domain.cells_x=9 \
          --set domain.cells=30 -o "$out/${name}_9x30.h5" ;;
      thesis_sandpile_2d)
        # a small sand pile: 28 x 14 cells (5 mm), the 10 mm inlet at 0.35
        # m/s (7x the scenario's mass flux: at the scenario's the grains run
        # out into a flat layer, docs/model/twod.md "thesis_sandpile_2d"), the
        # solid regime, to t = 1 s (8 s of CPU); then its base pressure
        "$root/$build/continuum/ekm" run "$ini" --set domain.cells_x=28 --set domain.cells=14 \
          --set top.w=-0.35 --set run.t_end=1 --set run.output_dt=0.25 --set hypo.enabled=1 \
          -o "$out/${name}_small.h5"
        /usr/bin/python3 -B "$root/figures/pile2d.py" "$out/${name}_small.h5" "$out/${name}_small" \
          --times 0.25,0.5,0.75,1 --base-time 1 >/dev/null
        jq -r '.base_time as $b | "\(.input.scenario) (28 x 14 cells, w = -0.35 m/s, solid regime) at t = \($b.time.value) s: " +
          "bed: \($b.bed); base pressure P(centre)/P(max) = \($b.base_pressure.ratio_centre_to_max.value // "n/a")" +
          "; dip: \(if $b.dip.value == null then "n/a (\($b.dip.reason))" else ($b.dip.value | tostring) end)" +
          " (figures: '"$out/${name}_small"'/)"' "$out/${name}_small/pile2d.json" ;;
      *) echo "$name: 2D ($nx cells along x): skipped" ;;
    esac
    continue
  fi
  "$root/$build/continuum/ekm" run "$ini" -o "$out/$name.h5"
done
echo
echo "== 2. the smoke validation campaign (make campaign SIZE=smoke) -> results/smoke/"
make -s -C "$root" campaign SIZE=smoke BUILD="$build" JOBS="${JOBS:-2}" -j "${JOBS:-2}"
cd "$root"
/usr/bin/python3 -B scripts/campaign/demo_summary.py results/smoke runs/demo/continuum
