#!/usr/bin/env bash
# cg2d_cli_test.sh: the command line of `ekmcompare cg --axes x,z` and
# `ekmcompare base`: outputs and their layout, one-line errors with the
# exit codes of docs/exit-codes.md and no output left behind, and the
# default 1D output unchanged by `--axes z` (byte for byte, as CSV).
# usage: cg2d_cli_test.sh EKMCOMPARE CG_SYNTH FIXTURES WORKDIR
set -u
ekmc=$1 synth=$2 fx=$3 work=$4
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
fails=0
fail() { echo "FAIL: $*" >&2; fails=$((fails + 1)); }

# expect CODE PATTERN -- command...: exit code, one stderr line matching PATTERN
expect() {
  local code=$1 pat=$2; shift 3
  "$@" > out.txt 2> err.txt; local rc=$?
  [ "$rc" -eq "$code" ] || fail "$*: exit $rc, expected $code ($(cat err.txt))"
  if [ "$code" -ne 0 ]; then
    [ "$(wc -l < err.txt)" -eq 1 ] || fail "$*: expected one error line, got: $(cat err.txt)"
    grep -qE -- "$pat" err.txt || fail "$*: message '$(cat err.txt)' does not match '$pat'"
  fi
}

"$synth" a.dump text 800 4 && "$synth" b.dump text 800 4 && "$synth" pile.dump pile &&
  "$synth" nofz.dump pile_nofz || fail "cg_synth"
sed 's/^0.0000000000000000e+00 5.0000000000000003e-02$/0.0000000000000000e+00 6.0000000000000003e-02/' \
  b.dump > wide.dump
cmp -s b.dump wide.dump && fail "wide.dump: the box was not changed"

# --axes z is the default 1D profile, byte for byte
expect 0 "" -- "$ekmc" cg "$fx/lammps_time.dump" --rho-p 2500 --bins 8 --csv d1.csv --quiet
expect 0 "" -- "$ekmc" cg "$fx/lammps_time.dump" --rho-p 2500 --bins 8 --axes z --csv d2.csv --quiet
cmp -s d1.csv d2.csv || fail "--axes z: CSV differs from the default"

# the 2D grid: datasets [nt][nz][nx], /x /z /t, attributes, sidecar, CSV
expect 0 "" -- "$ekmc" cg a.dump --axes x,z --every 2 -o g.h5 --csv g.csv --quiet
[ -f g.xdmf ] || fail "--axes x,z: no sidecar g.xdmf"
h5dump -H -d phi g.h5 | grep -q "( 2, 200, 50 )" || fail "--axes x,z: phi is not [2][200][50]"
for d in x z t nsnapshots rho T kxx kzz kxz P sxx szz sxz vx_se; do
  h5dump -H -d "$d" g.h5 > /dev/null 2>&1 || fail "--axes x,z: no dataset /$d"
done
for a in inputs axis kernel width dx dz lo hi x_lo x_hi window code_version snapshots_used averaged_length; do
  h5dump -a "$a" g.h5 > /dev/null 2>&1 || fail "--axes x,z: no root attribute $a"
done
h5dump -a axis g.h5 | grep -q '"x,z"' || fail "--axes x,z: attribute axis"
grep -q 'Dimensions="201 2 51"' g.xdmf || fail "g.xdmf: expected a 3DCoRectMesh of 200 x 50 cells"
head -1 g.csv | grep -q '^t,x,z,phi,phi_se,rho,rho_se' || fail "g.csv: bad header"
[ "$(wc -l < g.csv)" -eq $((2 * 10000 + 1)) ] || fail "g.csv: expected 20000 rows"
expect 0 "" -- "$ekmc" cg a.dump b.dump --axes x,z --ensemble -o e.h5 --quiet
h5dump -a runs e.h5 | grep -q "(0): 2" || fail "--ensemble: attribute runs"

# bad command lines (exit 1) and bad inputs (exit 2), no output left
expect 1 "--axes: expected z .* or x,z .*got 'x,y'" -- "$ekmc" cg a.dump --axes x,y -o bad.h5
expect 1 "--axes: expected" -- "$ekmc" cg a.dump --axes xz -o bad.h5
expect 1 "--ensemble: expected at least two dumps" -- "$ekmc" cg a.dump --axes x,z --ensemble -o bad.h5
expect 1 "--ensemble: expected --axes x,z" -- "$ekmc" cg a.dump b.dump --ensemble -o bad.h5
expect 1 "--ensemble: one window per run" -- "$ekmc" cg a.dump b.dump --axes x,z --ensemble --every 2 -o bad.h5
expect 1 "--kernel: bins .* no exact 2D form" -- "$ekmc" cg a.dump --axes x,z --kernel bins -o bad.h5
expect 1 "--bins: expected NX,NZ" -- "$ekmc" cg a.dump --axes x,z --bins 10 -o bad.h5
expect 1 "--bins NX,NZ: expected --axes x,z" -- "$ekmc" cg a.dump --bins 10,12 -o bad.h5
expect 1 "expected --stress or --pairs, not both" -- \
  "$ekmc" cg a.dump --axes x,z --stress c_s --pairs p.dump --pair-columns id1,id2,fx,fy,fz -o bad.h5
expect 2 "wide.dump:[0-9]+: ITEM: BOX BOUNDS: x: expected the box of the first run" -- \
  "$ekmc" cg a.dump wide.dump --axes x,z --ensemble -o bad.h5
expect 2 "nofz.dump:9: ITEM: ATOMS has no column 'fz'" -- "$ekmc" base nofz.dump -o bad.h5
expect 2 "pile.dump:9: expected floor grains \(atoms of type 5" -- "$ekmc" base pile.dump --floor-type 5 -o bad.h5
expect 1 "--floor-type: expected an atom type" -- "$ekmc" base pile.dump --floor-type two -o bad.h5
expect 1 "base: expected -o OUT.h5 and/or --csv" -- "$ekmc" base pile.dump
expect 1 "--range: expected a range symmetric about --centre" -- \
  "$ekmc" base pile.dump --centre 0.08 --range 0:0.1 -o bad.h5
expect 3 "" -- "$ekmc" base pile.dump -o pile.dump
ls bad.* > /dev/null 2>&1 && fail "an error left an output behind: $(ls bad.*)"

# base: outputs
expect 0 "" -- "$ekmc" base pile.dump -o base.h5 --csv base.csv --dx 0.008 --quiet
head -1 base.csv | grep -q '^x,p_base,p_base_se,p_base_se_fold$' || fail "base.csv: bad header"
[ "$(wc -l < base.csv)" -eq 21 ] || fail "base.csv: expected 20 bins"
for d in x p_base p_base_se p_base_se_fold p_base_runs; do
  h5dump -H -d "$d" base.h5 > /dev/null 2>&1 || fail "base: no dataset /$d"
done
h5dump -a y_period base.h5 | grep -q "0.004" || fail "base: attribute y_period"

[ "$fails" -eq 0 ] && echo "cg2d_cli_test: all passed"
exit $((fails > 0))
