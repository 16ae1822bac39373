#!/usr/bin/python3
"""check_sandpile_test.py: check_run.sh --sandpile on synthetic finished runs.

    tests/dem/check_sandpile_test.py WORKDIR      (EKMSCENARIO= names the ekmscenario binary)

No DEM engine: each case is a run folder written by hand (run.json status
ok, vars.txt, screen.txt with the deck's EKMDEM lines, atoms.dump with the
contract's columns) whose last frame is a pile at rest on a plate of 10
floor grains (lp = 10 d in a box 20 d wide): one pile grain on each floor
grain, each floor grain carrying exactly its pile grain's weight. The
scenario is scenarios/sandpile.ini (lammps, ref: rest_ke 1e-5 J/kg).

  1. at rest: exit 0;
  2. a grain sliding off the plate's edge (centre at z = 0.3 d > 0 but
     x - lx/2 = 5.3 d beyond lp/2 = 5 d, moving at 0.3 m/s, carried by no
     floor grain), so the deck's ke_per_mass (every grain with z > 0) is
     above the limit: exit 0, the grain is not part of the pile (before the
     fix: exit 4, "not at rest" and the weight 10% above the floor force);
  3. the same beyond the left edge (x - lx/2 = -5.3 d): exit 0;
  4. the same grain moving on the plate (x - lx/2 = 3.5 d) with the floor
     carrying it: exit 4 and "pile not at rest" (the check still sees a
     moving pile);
  5. case 2 whose last frame is not the run's last step (EKMDEM_DONE
     steps): the check falls back to the deck's number: exit 4;
  6. the weight check on the plate: a pile grain on the plate that the
     floor does not carry (a floor force 10% short): exit 4 and the 1%
     message;
  7. scripts/dem/pile_summary.py (its dump reader: scripts/dem/pile_dump.py,
     shared with pile_stats.py) on case 2: the pile is the 10 grains on the
     plate, base force / weight = 1 to 1e-6 (11 grains and 0.909 before).
Exit 0 if every check holds, 1 otherwise (one line per failed check).
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
CHECK = os.path.join(ROOT, "scripts", "dem", "check_run.sh")
D, G, RHO = 0.002, 9.81, 2500.0
LX, LP, LY = 20 * D, 10 * D, D
M = RHO * 3.141592653589793 / 6 * D ** 3  # one grain of diameter d
COLS = ("id type x y z vx vy vz radius mass omegax omegay omegaz "
        "c_sa[1] c_sa[2] c_sa[3] c_sa[4] c_sa[5] c_sa[6] fx fy fz")
failures = []


def check(ok, what):
    print(("ok: " if ok else "FAILED: ") + what)
    if not ok:
        failures.append(what)


def row(aid, typ, x, z, vx=0.0, fz=0.0):
    return "%d %d %.9g %.9g %.9g %.9g 0 0 %.9g %.9g 0 0 0 0 0 0 0 0 0 0 0 %.9g" % (
        aid, typ, x, 0.5 * D, z, vx, 0.5 * D, M, fz)


def write_run(path, extra=None, carried=True, step=420000, done=420000, short=False):
    """A run folder; extra = (x - lx/2 in d, z in d, vx): one more pile grain."""
    os.makedirs(path, exist_ok=True)
    rows, aid, ke, mass = [], 0, 0.0, 0.0
    xs = [LX / 2 - LP / 2 + (i + 0.5) * D for i in range(10)]
    for i, x in enumerate(xs):
        aid += 1
        load = M * G
        if extra is not None and carried and abs(x - (LX / 2 + extra[0] * D)) < 0.5 * D:
            load += M * G  # the floor grain under the extra grain carries it too
        if short and i == 0:
            load = 0.0  # the floor does not carry the first pile grain
        rows.append(row(aid, 2, x, -0.5 * D, fz=-load))
    for x in xs:
        aid += 1
        rows.append(row(aid, 1, x, 0.5 * D))
        mass += M
    if extra is not None:
        aid += 1
        rows.append(row(aid, 1, LX / 2 + extra[0] * D, extra[1] * D, vx=extra[2]))
        mass += M
        ke += 0.5 * M * extra[2] ** 2
    with open(os.path.join(path, "atoms.dump"), "w") as f:
        for s in (step - 10000, step):
            f.write("ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ATOMS\n%d\nITEM: BOX BOUNDS pp pp fm\n" % (s, len(rows)))
            f.write("0 %.9g\n0 %.9g\n%.9g %.9g\n" % (LX, LY, -1.5 * D, 40 * D))
            f.write("ITEM: ATOMS " + COLS + "\n" + "\n".join(rows) + "\n")
    # the deck's numbers: every grain with z > 0 (the extra one too)
    with open(os.path.join(path, "screen.txt"), "w") as f:
        f.write("EKMDEM_MASS target %.9g inserted %.9g final %.9g ninserted %d ntarget %d ke_per_mass %.9g\n"
                % (mass, mass, mass, aid - 10, aid - 10, ke / mass))
        f.write("EKMDEM_PILE floor_fz 0 weight %.9g sunk 0\n" % (mass * G))
        f.write("EKMDEM_DONE natoms %d steps %d\n" % (aid, done))
    with open(os.path.join(path, "vars.txt"), "w") as f:
        f.write("d = %g\nseed = 1\ng = %g\nlx = %g\nlp = %g\nly = %g\nsource_width = 8\n" % (D, G, LX, LP, LY))
    json.dump({"scenario": "sandpile", "engine": "lammps", "size": "ref", "point": "source8",
               "scenario_file": "scenarios/sandpile.ini", "status": "ok",
               "wall_time_s": 1.0, "particles": aid},
              open(os.path.join(path, "run.json"), "w"), indent=1)
    for f in ("deck.in", "log.txt", "pairs.dump"):
        open(os.path.join(path, f), "w").write("synthetic\n")
    return path


def run(path):
    r = subprocess.run([CHECK, "--sandpile", path], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def main():
    if len(sys.argv) != 2:
        print("usage: check_sandpile_test.py WORKDIR", file=sys.stderr)
        return 2
    work = sys.argv[1]
    rc, out = run(write_run(os.path.join(work, "rest")))
    check(rc == 0, "1. a pile at rest on the plate: exit %d (0 expected)\n%s" % (rc, out))
    rc, out = run(write_run(os.path.join(work, "sliding_off"), extra=(5.3, 0.3, 0.3), carried=False))
    check(rc == 0 and "1 grains above z = 0 beyond the plate left out" in out,
          "2. a grain sliding off the plate's edge is not in the pile: exit %d (0 expected)\n%s" % (rc, out))
    rc, out = run(write_run(os.path.join(work, "sliding_off_left"), extra=(-5.3, 0.3, -0.3), carried=False))
    check(rc == 0, "3. a grain sliding off the left edge is not in the pile: exit %d (0 expected)\n%s" % (rc, out))
    rc, out = run(write_run(os.path.join(work, "moving_on_plate"), extra=(3.5, 0.5, 0.3), carried=True))
    check(rc == 4 and "pile not at rest" in out and "more than 1%" not in out,
          "4. a moving grain on the plate fails the rest check: exit %d (4 expected)\n%s" % (rc, out))
    rc, out = run(write_run(os.path.join(work, "not_last"), extra=(5.3, 0.3, 0.3), carried=False, done=430000))
    check(rc == 4 and "pile not at rest" in out and "deck's ke_per_mass" in out,
          "5. last frame not the run's end: the deck's ke_per_mass decides: exit %d (4 expected)\n%s" % (rc, out))
    rc, out = run(write_run(os.path.join(work, "short"), short=True))
    check(rc == 4 and "differs from the weight of the pile by more than 1%" in out,
          "6. a floor force 10%% short of the weight on the plate: exit %d (4 expected)\n%s" % (rc, out))
    r = subprocess.run(["/usr/bin/python3", "-B", os.path.join(ROOT, "scripts", "dem", "pile_summary.py"),
                        os.path.join(work, "sliding_off")], capture_output=True, text=True)
    try:
        j = json.loads(r.stdout)
        ok = j["n_grains"] == 10 and abs(j["base_over_weight"] - 1) < 1e-6
        got = "%d grains, base/weight %.6f" % (j["n_grains"], j["base_over_weight"])
    except (ValueError, KeyError):
        ok, got = False, "exit %d: %s" % (r.returncode, r.stderr.strip())
    check(ok, "7. pile_summary.py: the grain sliding off is not in the pile's weight (%s)" % got)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
