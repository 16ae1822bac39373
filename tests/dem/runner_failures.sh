#!/usr/bin/env bash
# runner_failures.sh OUTDIR: the DEM runner fails loudly, with the documented
# exit status and a run.json status, on each kind of failure it promises to
# catch (scripts/dem/run.sh header).
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
run=$root/scripts/dem/run.sh
out=${1:-$(mktemp -d)}; mkdir -p "$out"
fail=0
expect() { # expect STATUS DESCRIPTION CMD...
  local want=$1 what=$2; shift 2
  "$@" > "$out/last.txt" 2>&1; local rc=$?
  if [ $rc -eq "$want" ]; then echo "ok: $what (exit $rc)"
  else echo "FAIL: $what: exit $rc, expected $want"; sed 's/^/  | /' "$out/last.txt"; fail=1; fi
}
# usage errors: exit 1; scenario errors (the reader's): exit 2
expect 1 "unknown engine" "$run" -o "$out" chute nosuchengine smoke
expect 1 "unknown size" "$run" -o "$out" chute lammps huge
expect 2 "-s without =" "$run" -o "$out" -s dt chute lammps smoke
grep -q "run.sh: -s 'dt': expected KEY=VALUE" "$out/last.txt" || { echo "FAIL: message does not name the -s"; fail=1; }
expect 2 "malformed number" "$run" -o "$out" -s dt=1e-5x chute lammps smoke
grep -q "dt.*1e-5x" "$out/last.txt" || { echo "FAIL: message does not name the key and value"; fail=1; }
expect 2 "unknown [dem] key" "$run" -o "$out" -s no_such_key=1 chute lammps smoke
grep -q "no_such_key" "$out/last.txt" || { echo "FAIL: message does not name the unknown key"; fail=1; }
# chute.ini without its [dem] section (the rest is a valid scenario)
sed '/^\[dem\]/,/^\[compare\]/{/^\[compare\]/!d}' "$root/scenarios/chute.ini" > "$out/nodem.ini"
expect 2 "scenario file without [dem]" "$run" -o "$out" -c "$out/nodem.ini" collision lammps smoke
grep -q "nodem.ini: no \[dem\] section" "$out/last.txt" || { echo "FAIL: message does not say there is no [dem]"; fail=1; }
sed '/^friction *=/d' "$root/scenarios/chute.ini" > "$out/nokey.ini"
expect 2 "missing [dem] key" "$run" -o "$out" -c "$out/nokey.ini" collision lammps smoke
grep -q "nokey.ini: \[dem\] friction: missing key" "$out/last.txt" || { echo "FAIL: message does not name the missing key"; fail=1; }
# engine or ekmscenario missing: exit 7
expect 7 "ekmscenario not built" env EKMSCENARIO=$out/no-such-ekmscenario "$run" -o "$out" chute lammps smoke
grep -q "ekmscenario not built: run make build" "$out/last.txt" || { echo "FAIL: no 'ekmscenario not built' line"; fail=1; }
expect 7 "engine missing" env LAMMPS_EXE=no-such-lmp "$run" -o "$out" chute lammps smoke
# deck error: exit 4, status deck_error, engine message kept. The reader
# refuses values an engine would reject (dt <= 0, poisson >= 0.5), so the
# engines' own failures are played by stand-ins printing what they print.
fake() { # fake NAME LINES...: an engine that answers -h and prints LINES
  local f=$out/$1; shift
  { printf '#!/bin/sh\ncase "$1" in -h) echo "LAMMPS (2 Aug 2023)"; exit 0 ;; esac\n'
    for l in "$@"; do printf 'echo "%s"\n' "$l"; done; } > "$f"
  chmod +x "$f"
}
fake err_lmp "ERROR: Illegal timestep command (src/input.cpp:1234)" "Last command: timestep -1e-05"
expect 4 "deck error (LAMMPS ERROR line)" env LAMMPS_EXE=$out/err_lmp "$run" -f -o "$out" collision lammps smoke
grep -q '"status": "deck_error"' "$out/collision/lammps-smoke/run.json" || { echo "FAIL: run.json status is not deck_error"; fail=1; }
grep -q '"message": "ERROR' "$out/collision/lammps-smoke/run.json" || { echo "FAIL: run.json does not carry the engine's message"; fail=1; }
fake err_lig "ERROR on proc 0: Illegal timestep command (input.cpp:1234)"
expect 4 "deck error (LIGGGHTS 'ERROR on proc' line)" env LIGGGHTS_EXE=$out/err_lig "$run" -f -o "$out" collision liggghts smoke
grep -q '"message": "ERROR' "$out/collision/liggghts-smoke/run.json" || { echo "FAIL: LIGGGHTS message lost"; fail=1; }
# NaN in thermo output: exit 4
fake nan_lmp "Step Atoms Time KinEng" "       0        2   0   0.1" "    1000        2   0.01   nan" "Loop time of 0.1 on 1 procs" "EKMDEM_DONE natoms 2 steps 1000"
expect 4 "NaN in thermo output" env LAMMPS_EXE=$out/nan_lmp "$run" -f -o "$out" collision lammps smoke
grep -q '"status": "nan"' "$out/collision/lammps-smoke/run.json" || { echo "FAIL: run.json status is not nan"; fail=1; }
# lost atoms (a huge modulus blows the pairs out of the closed box): exit 4
expect 4 "lost atoms" "$run" -f -o "$out" -s youngs=1e30 collision lammps smoke
grep -q '"status": "lost_atoms"' "$out/collision/lammps-smoke/run.json" || { echo "FAIL: run.json status is not lost_atoms"; fail=1; }
# timeout: exit 4, status timeout
expect 4 "timeout" "$run" -f -o "$out" -s timeout=1 -s t_flow=100 chute lammps smoke
grep -q '"status": "timeout"' "$out/chute/lammps-smoke/run.json" || { echo "FAIL: run.json status is not timeout"; fail=1; }
# a SIGTERM while the engine runs ends the runner as a signal does (128+15),
# not with a made-up status
printf '#!/bin/sh\ncase "$1" in -h) echo "LAMMPS (2 Aug 2023)"; exit 0 ;; esac\nsleep 4\nexit 1\n' > "$out/slow_lmp"
chmod +x "$out/slow_lmp"
LAMMPS_EXE=$out/slow_lmp "$run" -f -o "$out/term" collision lammps smoke > "$out/term.txt" 2>&1 &
pid=$!
for _ in $(seq 100); do grep -q "running in" "$out/term.txt" 2> /dev/null && break; sleep 0.1; done
sleep 0.3; kill -TERM $pid; wait $pid; rc=$?
if [ $rc -eq 143 ]; then echo "ok: SIGTERM during a run (exit 143)"
else echo "FAIL: SIGTERM during a run: exit $rc, expected 143"; sed 's/^/  | /' "$out/term.txt"; fail=1; fi
sleep 4   # the orphaned fake engine ends
# unsupported engine/scenario: exit 7
expect 7 "simple_shear in LIGGGHTS is unsupported" "$run" -o "$out" simple_shear liggghts smoke
expect 7 "simple_shear_p in LIGGGHTS is unsupported" "$run" -o "$out" simple_shear_p liggghts smoke
# a finished run is not redone without -f
expect 0 "collision (good run)" "$run" -f -o "$out" collision lammps smoke
expect 0 "finished run kept" "$run" -o "$out" collision lammps smoke
grep -q "is done" "$out/last.txt" || { echo "FAIL: finished run was redone"; fail=1; }
# the helper scripts: usage 1, a missing run file 3, a failed check or run 4
expect 1 "check_run.sh without a folder" "$root/scripts/dem/check_run.sh"
expect 3 "check_run.sh on a folder without run.json" "$root/scripts/dem/check_run.sh" "$out/nokey.ini.d"
grep -q "no run.json" "$out/last.txt" || { echo "FAIL: check_run does not name run.json"; fail=1; }
expect 1 "monitor_stats.sh without a folder" "$root/scripts/dem/monitor_stats.sh"
expect 1 "monitor_stats.sh with an unknown option" "$root/scripts/dem/monitor_stats.sh" -x "$out"
expect 3 "monitor_stats.sh on a folder without monitor.txt" "$root/scripts/dem/monitor_stats.sh" "$out"
expect 1 "chute_profile.sh with an unknown option" "$root/scripts/dem/chute_profile.sh" -x "$out"
expect 3 "chute_profile.sh on a folder without a run" "$root/scripts/dem/chute_profile.sh" "$out"
expect 4 "collision.sh whose DEM run fails" "$root/scripts/dem/collision.sh" -o "$out" -c "$out/nokey.ini" lammps
grep -q "collision run failed" "$out/last.txt" || { echo "FAIL: collision.sh does not report the failed run"; fail=1; }
expect 4 "collision.sh restitution off target (tolerance 0)" "$root/scripts/dem/collision.sh" -o "$out" -t 0 lammps
grep -q "FAIL" "$out/last.txt" || { echo "FAIL: collision.sh does not mark the mismatch"; fail=1; }
exit $fail
