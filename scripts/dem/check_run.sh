#!/usr/bin/env bash
# check_run.sh: assert that a finished DEM case is complete and usable.
#
#   scripts/dem/check_run.sh [--filling | --sandpile | --pressure] DIR
#
# Checks: run.json has status "ok"; every dump is what the run recorded
# in run.json "dumps" (frames, bytes, sha256: not changed after the run);
# atoms.dump exists, has at least two
# frames and its ITEM: ATOMS header names the columns the comparison tool
# needs (id type x y z vx vy vz radius mass c_sa[1..6]); pairs.dump exists;
# log and deck copies exist. With --filling also the mass balance: mass in
# the box at the end equals the mass inserted (to 1e-9 relative) and the
# scenario's target rho phi |w| A t_stop to 1%, and the bed is at rest
# (kinetic energy per unit mass below [dem] rest_ke, as the scenario reader
# resolves it for the run's scenario file, engine and size: `ekmscenario
# ... --json`, EKMSCENARIO= names the ekmscenario binary). With --sandpile the rest check, the
# source's insertion (the mass inserted, EKMDEM_MASS inserted, equals its
# target to 1%; the final mass, the grains still on the plate, is
# a result: what rolls off the plate is deleted), and the dump contract of
# docs/dem.md "Sand pile": atoms.dump has the columns of dumps.inc plus
# fx fy fz, in that order; in its last frame the floor grains (type 2) are
# still (v = 0: not time-integrated), and the force on them,
# -(sum of their fz), equals the weight g * (mass of the pile grains,
# type 1, on the plate) to 1%. A pile grain is on the plate if its centre
# is above the plate's top (z > 0) and within its width (|x - xmid| <
# lp/2, xmid the middle of the dump's box, lp of vars.txt; without lp the
# whole box): one sliding off the plate's edge (z > 0 but beyond it) is
# not part of the pile. The sand pile's rest check is made on the same
# grains, from the dump's last frame (translational kinetic energy per
# mass, as the deck's EKMDEM_MASS ke_per_mass, which counts every grain
# with z > 0) when that frame is the run's last step (EKMDEM_DONE steps),
# else on the deck's number. With --pressure (simple_shear_p) the
# barostat: the mean normal stress Pzz over the last half of monitor.txt
# equals the target `pressure` of vars.txt within 3 block standard errors
# (monitor_stats.sh). Exit status (docs/exit-codes.md):
# 0 all pass; 1 usage; 3 run.json or another file of the run is missing;
# 2 a file is there but not as expected (status not ok, a dump that
# differs from its run.json record, too few frames, a
# missing column or EKMDEM_MASS marker, no [dem] rest_ke, no pressure in
# vars.txt, no v_Pzz column in monitor.txt, a sand-pile dump without the
# contract's columns); 4 the filling or sand-pile mass balance or rest
# check, the floor force or still floor, or the barostat check, fails; 7 ekm not built. The first
# failing kind of check gives the status.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
filling=0; pressure=0; sandpile=0
case ${1:-} in
  --filling) filling=1; shift ;;
  --sandpile) filling=1; sandpile=1; shift ;;
  --pressure) pressure=1; shift ;;
esac
[ $# -eq 1 ] || { echo "usage: check_run.sh [--filling | --sandpile | --pressure] DIR" >&2; exit 1; }
dir=$1; fail=0
# bad STATUS MESSAGE: report a failed check; the first one's status wins
bad() { echo "check_run: $dir: $2" >&2; [ "$fail" -ne 0 ] || fail=$1; }

[ -f "$dir/run.json" ] || { bad 3 "no run.json"; exit 3; }
grep -q '"status": "ok"' "$dir/run.json" || bad 2 "status is not ok: $(grep -o '"status": "[a-z_]*"' "$dir/run.json")"
for f in deck.in vars.txt log.txt screen.txt atoms.dump pairs.dump; do
  [ -s "$dir/$f" ] || bad 3 "missing or empty $f"
done
# the dumps are what the run produced (run.json "dumps": frames, bytes,
# sha256; scripts/dem/dump_record.sh)
chk=$("$here/dump_record.sh" verify "$dir" 2>&1); r=$?
if [ $r -ne 0 ]; then
  while IFS= read -r l; do bad "$([ $r -eq 3 ] && echo 3 || echo 2)" "${l#dump_record.sh: "$dir"/}"; done <<< "$chk"
elif [ -n "$chk" ]; then echo "check_run: $dir: ${chk#dump_record.sh: }" >&2
fi
if [ -s "$dir/atoms.dump" ]; then
  frames=$(grep -c '^ITEM: TIMESTEP' "$dir/atoms.dump")
  [ "$frames" -ge 2 ] || bad 2 "atoms.dump has $frames frame(s), expected >= 2"
  hdr=$(grep -m1 '^ITEM: ATOMS' "$dir/atoms.dump")
  for c in id type x y z vx vy vz radius mass 'c_sa\[1\]' 'c_sa\[6\]'; do
    echo "$hdr" | grep -qE " $c( |$)" || bad 2 "atoms.dump: ITEM: ATOMS has no column '${c//\\/}'"
  done
fi
if [ $filling -eq 1 ]; then
  line=$(grep '^EKMDEM_MASS' "$dir/screen.txt")
  [ -n "$line" ] || { bad 2 "no EKMDEM_MASS line in screen.txt"; exit "$fail"; }
  ini=$root/$(jq -r .scenario_file "$dir/run.json")
  ekmscenario=${EKMSCENARIO:-$root/build/scenario/ekmscenario}
  [ -x "$ekmscenario" ] || { echo "check_run: ekmscenario not built: run make build (no executable $ekmscenario)" >&2; exit 7; }
  resolved=$("$ekmscenario" "$ini" --engine "$(jq -r .engine "$dir/run.json")" \
             --size "$(jq -r .size "$dir/run.json")" --json) || exit
  rest=$(jq -r '.keys["dem.rest_ke"].value // empty' <<< "$resolved")
  [ -n "$rest" ] || { bad 2 "$ini: [dem] rest_ke: missing key"; exit "$fail"; }
  what=filling; [ $sandpile -eq 1 ] && what=sandpile
  echo "$line" | awk -v rest="$rest" -v dir="$dir" -v what="$what" '{
    for (i = 2; i < NF; i += 2) v[$i] = $(i + 1)
    t = v["target"]; ins = v["inserted"]; fin = v["final"]; ke = v["ke_per_mass"]
    e1 = (fin - ins) / ins; if (e1 < 0) e1 = -e1
    e2 = (fin - t) / t;     if (e2 < 0) e2 = -e2
    f = 0
    if (what == "sandpile") {
      # the pile sits on a finite plate: what rolls off it is deleted (the
      # sink of the deck), so the final mass is a result; the source must have
      # inserted every grain of its target
      ni = v["ninserted"]; nt = v["ntarget"]; e3 = (ins - t) / t; if (e3 < 0) e3 = -e3
      printf "%s mass: target %.6g kg (%d grains), inserted %.6g kg (%d grains), final %.6g kg (%.1f%% of it rolled off the plate), ke/mass %.3g J/kg (limit %s)\n", what, t, nt, ins, ni, fin, 100 * (ins - fin) / ins, ke, rest
      if (e3 > 0.01) { print "check_run: " dir ": the source inserted " ins " kg, expected " t " kg (1%)" > "/dev/stderr"; f = 1 }
      if (!(fin > 0) || fin > ins * (1 + 1e-9)) { print "check_run: " dir ": final mass " fin " kg, expected > 0 and at most the " ins " kg inserted" > "/dev/stderr"; f = 1 }
    } else {
      printf "%s mass: target %.6g kg, inserted %.6g kg, final %.6g kg (vs target %.3f%%), ke/mass %.3g J/kg (limit %s)\n", what, t, ins, fin, 100 * e2, ke, rest
      if (e1 > 1e-9) { print "check_run: " dir ": mass lost after insertion" > "/dev/stderr"; f = 1 }
      if (e2 > 0.01) { print "check_run: " dir ": final mass differs from the inflow target by more than 1%" > "/dev/stderr"; f = 1 }
    }
    # the sand pile: the rest check is made on the dump (grains on the plate), below
    if (what != "sandpile" && ke + 0 > rest + 0) { print "check_run: " dir ": bed not at rest" > "/dev/stderr"; f = 1 }
    exit f }' || { [ "$fail" -ne 0 ] || fail=4; }
  deck_ke=$(echo "$line" | awk '{ for (i = 2; i < NF; i += 2) if ($i == "ke_per_mass") print $(i + 1) }')
  last_step=$(awk '$1 == "EKMDEM_DONE" { for (i = 2; i < NF; i += 2) if ($i == "steps") s = $(i + 1) } END { print s }' "$dir/screen.txt")
fi
if [ $sandpile -eq 1 ] && [ -s "$dir/atoms.dump" ]; then
  # the dump contract: dumps.inc's columns plus fx fy fz
  want="$(sed -n 's/^dump *da .* atoms\.dump \(.*\)$/\1/p' "$root/dem_inputs/$(jq -r .engine "$dir/run.json")/dumps.inc") fx fy fz"
  have=$(grep -m1 '^ITEM: ATOMS' "$dir/atoms.dump" | sed 's/^ITEM: ATOMS //; s/ *$//')
  [ "$have" = "$want" ] || { bad 2 "atoms.dump: columns '$have', expected '$want' (docs/dem.md \"Sand pile\")"; exit "$fail"; }
  g=$(awk '$1 == "g" { print $3 }' "$dir/vars.txt")
  [ -n "$g" ] || { bad 2 "no g in vars.txt"; exit "$fail"; }
  lp=$(awk '$1 == "lp" { print $3 }' "$dir/vars.txt")
  # the last frame: floor still, its force the pile's weight, and no force
  # on a floor grain no pile grain touches (none low enough, z < 3 of the
  # largest radii above the floor's top, within two largest diameters in
  # x, periodic): floor-floor contacts excluded (the jittered floor grains
  # overlap; their pairwise forces would cancel in the sum)
  # the pile: type 1 grains on the plate (z > 0, |x - xmid| < lp/2); its
  # weight, and its kinetic energy per mass for the rest check
  awk -v g="$g" -v dir="$dir" -v lp="$lp" -v rest="${rest:-}" -v deck_ke="${deck_ke:-}" -v last_step="${last_step:-}" '
    /^ITEM: TIMESTEP/ { getline step; nf = 0; fz = 0; m = 0; ke = 0; moving = 0; nfl = 0; nlow = 0; rmax = 0; off = 0; next }
    /^ITEM: BOX BOUNDS/ { getline; lx = $2 - $1; xmid = 0.5 * ($1 + $2); half = (lp == "" ? lx : 0.5 * lp); next }
    /^ITEM: ATOMS/ { for (i = 3; i <= NF; i++) c[$i] = i - 2; inatoms = 1; next }
    /^ITEM:/ { inatoms = 0; next }
    inatoms {
      if ($c["type"] == 2) { nfl++; fx_[nfl] = $c["x"]; fz_[nfl] = $c["fz"]; fz += $c["fz"]; if ($c["vx"] != 0 || $c["vy"] != 0 || $c["vz"] != 0) moving++; if ($c["radius"] > rmax) rmax = $c["radius"] }
      else if ($c["type"] == 1) {
        if ($c["z"] > 0) {
          dxm = $c["x"] - xmid; if (dxm < 0) dxm = -dxm
          if (dxm < half) { m += $c["mass"]; ke += 0.5 * $c["mass"] * ($c["vx"] * $c["vx"] + $c["vy"] * $c["vy"] + $c["vz"] * $c["vz"]) }
          else off++
        }
        nlow++; px[nlow] = $c["x"]; pz[nlow] = $c["z"]; if ($c["radius"] > rmax) rmax = $c["radius"] } }
    END {
      w = g * m; e = (m > 0 ? (-fz - w) / w : 1); if (e < 0) e = -e
      f = 0
      if (rest != "") {
        # the rest check on the grains on the plate, if this frame is the run'"'"'s end
        if (last_step != "" && step + 0 == last_step + 0) { kem = (m > 0 ? ke / m : 0); src = "last frame, grains on the plate" }
        else { kem = deck_ke; src = "the deck'"'"'s ke_per_mass (the last frame, step " step ", is not the run'"'"'s end, " last_step ")" }
        printf "sandpile rest: ke/mass %.3g J/kg (%s; %d grains above z = 0 beyond the plate left out), limit %s\n", kem, src, off, rest
        if (kem + 0 > rest + 0) { print "check_run: " dir ": pile not at rest" > "/dev/stderr"; f = 1 }
      }
      n = 0
      for (k = 1; k <= nlow; k++) if (pz[k] < 3 * rmax) { n++; lowx[n] = px[k] }
      free = 0; loaded = 0
      for (k = 1; k <= nfl; k++) {
        touched = 0
        for (q = 1; q <= n && !touched; q++) {
          dx = fx_[k] - lowx[q]; if (dx < 0) dx = -dx; if (lx > 0 && dx > lx / 2) dx = lx - dx
          if (dx < 4 * rmax) touched = 1
        }
        if (!touched) { free++; if (fz_[k] != 0) loaded++ }
      }
      printf "sandpile floor: step %d, %d floor grains (%d moving), force on the floor %.6g N, weight of the pile %.6g N (%.4f%%); %d floor grains no pile grain touches, %d of them with a force\n", step, nfl, moving, -fz, w, 100 * e, free, loaded
      if (moving > 0) { print "check_run: " dir ": floor grains moved (they must not be time-integrated)" > "/dev/stderr"; f = 1 }
      if (!(e <= 0.01)) { print "check_run: " dir ": the force on the floor differs from the weight of the pile by more than 1%" > "/dev/stderr"; f = 1 }
      if (free == 0) print "check_run: " dir ": note: every floor grain is under the pile, the floor-floor exclusion is not checked" > "/dev/stderr"
      if (loaded > 0) { print "check_run: " dir ": " loaded " floor grains no pile grain touches carry a force (floor-floor contacts must be excluded)" > "/dev/stderr"; f = 1 }
      exit f }' "$dir/atoms.dump" || { [ "$fail" -ne 0 ] || fail=4; }
fi
if [ $pressure -eq 1 ]; then
  target=$(awk '$1 == "pressure" { print $3 }' "$dir/vars.txt")
  [ -n "$target" ] || { bad 2 "no pressure in vars.txt"; exit 2; }
  "$here/monitor_stats.sh" "$dir" | awk -v t="$target" -v dir="$dir" '$1 == "v_Pzz" {
    m = $2; se = $4; dev = m - t; if (dev < 0) dev = -dev
    printf "pressure control: mean Pzz %.5g +- %.2g Pa, target %s Pa, |mean - target| = %.2f SE\n", m, se, t, (se > 0 ? dev / se : 0)
    found = 1; if (dev > 3 * se) { print "check_run: " dir ": mean Pzz differs from the target by more than 3 standard errors" > "/dev/stderr"; exit 4 } }
    END { if (!found) { print "check_run: " dir ": monitor.txt has no v_Pzz column" > "/dev/stderr"; exit 2 } }' ||
    { rc=$?; [ "$fail" -ne 0 ] || fail=$rc; }
fi
[ "$fail" -eq 0 ] && echo "check_run: $dir: ok"
exit "$fail"
