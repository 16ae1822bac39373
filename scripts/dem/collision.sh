#!/usr/bin/env bash
# collision.sh: binary-collision restitution test and calibration.
#
#   scripts/dem/collision.sh [-o OUTROOT] [-c FILE] [-t TOL] ENGINE
#       runs dem_inputs/ENGINE/collision.in with the contact parameters of
#       FILE's [dem] section (default scenarios/chute.ini): four head-on
#       collisions at 0.1, 0.5, 1 and 2 m/s; prints the realised restitution
#       of each and fails (exit 4) if any differs from [dem] restitution by
#       more than TOL (default 0.01).
#       [dem] restitution as the scenario reader resolves it (`ekmscenario
#       FILE --engine ENGINE --size smoke --json`; EKMSCENARIO= names the ekmscenario binary).
#   scripts/dem/collision.sh --calibrate [-c FILE] ENGINE
#       bisects the engine's input coefficient until the mean realised
#       restitution equals [dem] restitution; prints the value to put in
#       [dem] as <engine>.restitution_input.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=""; ini=$root/scenarios/chute.ini; tol=0.01; calib=0
while [ $# -gt 0 ]; do
  case $1 in
    -o) out=$2; shift 2 ;;
    -c) ini=$2; shift 2 ;;
    -t) tol=$2; shift 2 ;;
    --calibrate) calib=1; shift ;;
    -h) sed -n '2,15p' "$0"; exit 0 ;;
    *) break ;;
  esac
done
[ $# -eq 1 ] || { echo "usage: collision.sh [-o OUT] [-c FILE] [-t TOL] [--calibrate] ENGINE" >&2; exit 1; }
engine=$1
ekmscenario=${EKMSCENARIO:-$root/build/scenario/ekmscenario}
[ -x "$ekmscenario" ] || { echo "collision.sh: ekmscenario not built: run make build (no executable $ekmscenario)" >&2; exit 7; }
resolved=$("$ekmscenario" "$ini" --engine "$engine" --size smoke --json) || exit
target=$(jq -r '.keys["dem.restitution"].value // empty' <<< "$resolved")
[ -n "$target" ] || { echo "collision.sh: $ini: [dem] restitution: missing key" >&2; exit 2; }
[ -n "$out" ] || out=$(mktemp -d)

# realised IN: run with input coefficient IN (or the file's, if empty);
# prints "v e" lines
realised() {
  local -a s=()
  [ -n "$1" ] && s=(-s "restitution_input=$1")
  "$here/run.sh" -f -o "$out" -c "$ini" "${s[@]}" collision "$engine" smoke >/dev/null || return 1
  grep '^RESTITUTION' "$out/collision/$engine-smoke/screen.txt" | awk '{print $2, $3}'
}

if [ $calib -eq 1 ]; then
  lo=0.3; hi=0.99
  for i in $(seq 1 14); do
    mid=$(awk -v a=$lo -v b=$hi 'BEGIN { printf "%.5f", (a + b) / 2 }')
    mean=$(realised "$mid" | awk '{ s += $2; n++ } END { printf "%.6f", s / n }') || exit 4
    if awk -v m="$mean" -v t="$target" 'BEGIN { exit !(m < t) }'; then lo=$mid; else hi=$mid; fi
    echo "collision.sh: input $mid -> mean realised $mean" >&2
  done
  echo "$engine.restitution_input = $mid   ; realised $mean (target $target)"
  exit 0
fi

res=$(realised "") || { echo "collision.sh: $engine collision run failed (see $out/collision/$engine-smoke/screen.txt)" >&2; exit 4; }
echo "$res" | awk -v t="$target" -v tol="$tol" -v e="$engine" '
  { d = $2 - t; if (d < 0) d = -d; bad = (d > tol)
    printf "%s: impact %4.1f m/s  restitution %.4f  (target %s, |diff| %.4f)%s\n", e, $1, $2, t, d, bad ? "  FAIL" : ""
    if (bad) f = 4; n++ }
  END { if (n != 4) { print e ": expected 4 collisions, got " n; exit 4 } exit f }'
