#!/usr/bin/env bash
# sandpile_settle.sh ENGINE OUTDIR: the sand pile's settling ([dem]
# settle_max, docs/dem.md "Sand pile") in one engine, on the smoke sieve
# (point source42) stopped at t_end = 0.6 s, while it still moves (the pile
# is at rest from about 0.9-1.2 s):
#   A  settle_max = t_end (the default: no settling): the run ends at t_end
#      (60000 steps, its last dump frame), and the pile there is not at rest
#      (check_run.sh --sandpile: exit 4), so the settling has work to do;
#   B  the smoke settle_max (2.4 s): the run goes on past t_end in chunks of
#      dump_every steps and ends at rest (check_run.sh --sandpile passes) or
#      at settle_max; its last step is a dump frame; A's dumps are the first
#      bytes of B's (the same run up to t_end, step for step); run.json's
#      wall-time limit is [dem] timeout scaled by settle_max / t_end;
#   C  settle_max = 0.65 s: the run ends at settle_max (65000 steps) at
#      the latest, whether the pile is then at rest or not.
# Exit 0 when all hold, 1 otherwise (a line per failed check).
set -uo pipefail
[ $# -eq 2 ] || { echo "usage: sandpile_settle.sh ENGINE OUTDIR" >&2; exit 2; }
engine=$1 out=$2
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
run=$root/scripts/dem/run.sh check=$root/scripts/dem/check_run.sh
fail=0
bad() { echo "FAIL: $engine: $*"; fail=1; }
case_dir() { echo "$out/$1/sandpile/$engine-smoke/source42"; }
# done_steps DIR: the run's last step (EKMDEM_DONE steps)
done_steps() { sed -n 's/^EKMDEM_DONE .*steps \([0-9]*\).*/\1/p' "$1/screen.txt"; }
last_frame() { awk '/^ITEM: TIMESTEP/ { getline; s = $1 } END { print s }' "$1/atoms.dump"; }
# settle_ke DIR: the plate's kinetic energy per mass at the end (EKMDEM_SETTLE)
settle_ke() { sed -n 's/^EKMDEM_SETTLE .*ke_per_mass_plate \([^ ]*\).*/\1/p' "$1/screen.txt"; }

rm -rf "$out"; mkdir -p "$out" || { echo "FAIL: cannot create $out"; exit 1; }
for c in "A|settle_max=0.6" "B|" "C|settle_max=0.65"; do
  name=${c%%|*}; sets=(-s t_end=0.6); [ -n "${c#*|}" ] && sets+=(-s "${c#*|}")
  "$run" -f -o "$out/$name" "${sets[@]}" -P source42 sandpile "$engine" smoke > "$out/$name.log" 2>&1 ||
    { bad "run $name (${sets[*]}) failed: $(tail -1 "$out/$name.log")"; exit 1; }
  d=$(case_dir "$name")
  echo "$engine $name (${sets[*]}): ends at step $(done_steps "$d"), last frame $(last_frame "$d"), ke/mass on the plate $(settle_ke "$d") J/kg"
  [ "$(done_steps "$d")" = "$(last_frame "$d")" ] || bad "$name: the last dump frame $(last_frame "$d") is not the run's last step $(done_steps "$d")"
done
A=$(case_dir A) B=$(case_dir B) C=$(case_dir C)

# A: no settling, and a pile still moving at t_end
[ "$(done_steps "$A")" = 60000 ] || bad "A: ends at step $(done_steps "$A"), expected 60000 (t_end)"
"$check" --sandpile "$A" > "$out/A.check" 2>&1; r=$?
[ $r -eq 4 ] || bad "A: check_run.sh --sandpile exit $r, expected 4 (not at rest at t_end: the test needs a moving pile)"

# B: on past t_end, at rest or at settle_max (2.4 s = 240000 steps)
nb=$(done_steps "$B")
if [ -z "$nb" ] || [ "$nb" -le 60000 ]; then bad "B: ends at step $nb, expected after t_end (60000)"; fi
"$check" --sandpile "$B" > "$out/B.check" 2>&1; r=$?
if [ $r -ne 0 ] && [ "$nb" != 240000 ]; then
  bad "B: check_run.sh --sandpile exit $r and the run ended at step $nb, before settle_max (240000): $(grep check_run "$out/B.check" | head -2)"
fi
for f in atoms.dump pairs.dump; do
  n=$(stat -c %s "$A/$f")
  cmp -s -n "$n" "$A/$f" "$B/$f" || bad "B: $f: A's $f ($n bytes) is not the beginning of B's"
  [ "$(stat -c %s "$B/$f")" -gt "$n" ] || bad "B: $f: no frames after t_end"
done
tb=$(jq -r .timeout_s "$B/run.json") ta=$(jq -r .timeout_s "$A/run.json")
if [ "$ta" != 300 ] || [ "$tb" != 1200 ]; then
  bad "run.json timeout_s: A $ta (expected 300, [dem] smoke.timeout), B $tb (expected 1200 = 300 x 2.4 / 0.6)"
fi

# C: settle_max caps the settling
[ "$(done_steps "$C")" = 65000 ] || bad "C: ends at step $(done_steps "$C"), expected 65000 (settle_max 0.65 s)"
cmp -s -n "$(stat -c %s "$A/atoms.dump")" "$A/atoms.dump" "$C/atoms.dump" || bad "C: A's atoms.dump is not the beginning of C's"

[ $fail -eq 0 ] && echo "sandpile_settle: $engine: ok"
exit $fail
