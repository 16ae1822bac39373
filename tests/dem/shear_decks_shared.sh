#!/usr/bin/env bash
# shear_decks_shared.sh: the pressure-controlled simple-shear deck uses the
# grains, contact law and stress/temperature measurement of the
# volume-controlled one: the lines from `units` down to the compression
# block of dem_inputs/lammps/simple_shear_p.in are those of simple_shear.in,
# except that the compression target is phi0 instead of phi.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
block() { sed -n '/^units /,/^# compression to phi/p' "$1" | sed '$d'; }
a=$(block "$root/dem_inputs/lammps/simple_shear.in")
b=$(block "$root/dem_inputs/lammps/simple_shear_p.in" | sed 's/\${phi0}/${phi}/g')
[ "$(echo "$a" | wc -l)" -gt 50 ] || { echo "FAIL: shared block of simple_shear.in not found"; exit 1; }
if [ "$a" != "$b" ]; then
  echo "FAIL: simple_shear_p.in and simple_shear.in differ before the compression:"
  diff <(echo "$a") <(echo "$b")
  exit 1
fi
echo "shared block identical ($(echo "$a" | wc -l) lines)"
