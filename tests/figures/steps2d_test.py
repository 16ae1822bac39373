#!/usr/bin/python3
"""steps2d_test.py: figures/steps2d.py (the 2D filling's step-size study)
on synthetic runs with known differences, written under WORK (the build
directory). Python only: no ekm.

    /usr/bin/python3 steps2d_test.py SOURCE_DIR WORK

The runs are filling2d_test.py's synthetic box filling (18 x 60 cells,
bed phi 0.62 and 27 rows at the end, t = 0..4 s), one set "syn" of three:
  syn_r0.01   the filling as it is (the finest: smallest knob)
  syn_r0.1    the last frame changed: phi of the interior bed cell (row 5,
              column 3) + 1e-3, P of the wet cell (row 10, column 7) + 2 Pa,
              szz of the bottom cell of column 0 - 1 Pa (one more Pa of
              floor stress), stats.steps 5000
  syn_r1      as syn_r0.1 with the phi change on the bed's top row (row
              26, column 3: the surface cell, left out of the bed's phi
              difference but counted in its column's content)
Checks (steps2d.json's 7 digits: relative 1e-6): the finest run is syn_r0.01 and has
zero differences; syn_r0.1: the bed's phi difference 1e-3, the column
difference 1e-3 dz over the mean column's content, P 2 Pa over the
largest bed P, the floor's share from one Pa more of floor stress over dx
and the mass's change, steps 5000;
syn_r1: the bed's phi difference 0 (the surface cell is not the bed's),
the column difference as syn_r0.1; the monitoring T, P_max and bed arrival
as filling2d.py finds them; steps2d.md has a row per run; no NaN. Bad
inputs: a folder without runs: status 3 and one line; a run without /szz,
or one that ends at another time than the rest of its set: status 2 and
one line, no steps2d.json written. Exit status 77 (skipped)
when /usr/bin/python3 lacks numpy, matplotlib or h5py.
"""
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.dont_write_bytecode = True

import filling2d_test as S  # noqa: E402

failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL: " + msg, file=sys.stderr)


def close(a, b, rel=1e-9):
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


def steps2d(src, args):
    p = subprocess.run([sys.executable, os.path.join(src, "figures", "steps2d.py")] + list(args),
                       capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def changed(path, base, phi_cell):
    import h5py
    shutil.copy(base, path)
    with h5py.File(path, "r+") as f:
        f["phi"][-1, phi_cell[0], phi_cell[1]] += 1e-3
        f["P"][-1, 10, 7] += 2.0
        f["szz"][-1, 0, 0] -= 1.0
        f.attrs["stats.steps"] = 5000.0


def main():
    if len(sys.argv) != 3:
        print("usage: steps2d_test.py SOURCE_DIR WORK", file=sys.stderr)
        return 2
    src, work = sys.argv[1], sys.argv[2]
    try:
        import numpy  # noqa: F401
        import h5py
        import matplotlib  # noqa: F401
    except ImportError as e:
        print("skipped: %s (scripts/deps.sh figures)" % e)
        return 77
    shutil.rmtree(work, ignore_errors=True)
    runs = os.path.join(work, "runs")
    os.makedirs(runs)
    base = os.path.join(runs, "syn_r0.01.h5")
    S.make_run(base)
    changed(os.path.join(runs, "syn_r0.1.h5"), base, (5, 3))
    changed(os.path.join(runs, "syn_r1.h5"), base, (26, 3))
    out = os.path.join(work, "out")
    rc, _, err = steps2d(src, ["--runs", runs, "-o", out])
    check(rc == 0, "steps2d.py exit %d: %s" % (rc, err))
    if rc != 0:
        return 1
    with open(os.path.join(out, "steps2d.json")) as fh:
        text = fh.read()
    check("NaN" not in text and "Infinity" not in text, "no NaN or Infinity in steps2d.json")
    js = json.loads(text)
    st = js["sets"].get("syn_r")
    check(st is not None and st["finest"] == "syn_r0.01.h5", "one set syn_r, finest syn_r0.01.h5")
    rows = {r["run"]: r for r in st["runs"]}
    fin, r1, r2 = rows["syn_r0.01.h5"], rows["syn_r0.1.h5"], rows["syn_r1.h5"]
    for k in ("max_dphi_bed_from_finest", "max_dcolumn_mass_from_finest", "max_dP_from_finest_over_P_max"):
        check(fin[k]["value"] == 0.0, "the finest run's %s is 0 (got %r)" % (k, fin[k]["value"]))
    dz, dx = S.DZ, S.DX
    with h5py.File(base, "r") as f:
        phi_end = f["phi"][-1]
    col = 1e-3 * dz / (float(phi_end.sum(axis=0).mean()) * dz)
    pmax = fin["P_max"]["value"]
    check(close(r1["max_dphi_bed_from_finest"]["value"], 1e-3), "bed phi difference 1e-3 (got %r)"
          % r1["max_dphi_bed_from_finest"]["value"])
    check(close(r1["max_dcolumn_mass_from_finest"]["value"], col, 1e-6),
          "column difference %.6g (got %r)" % (col, r1["max_dcolumn_mass_from_finest"]["value"]))
    check(close(r1["max_dP_from_finest_over_P_max"]["value"], 2.0 / pmax, 1e-6),
          "P difference 2 Pa / P_max %.6g (got %r)" % (pmax, r1["max_dP_from_finest_over_P_max"]["value"]))
    mass0 = float(phi_end.sum()) * dx * dz * S.RHO_P
    mass1 = mass0 + 1e-3 * dx * dz * S.RHO_P
    # the floor force (1 Pa more over dx) over the weight (the phi change adds to the mass);
    # the JSON's 7 digits: shares to 5e-7
    want = fin["floor_share"]["value"] * mass0 / mass1 + dx / (S.G * mass1)
    check(abs(r1["floor_share"]["value"] - want) < 1e-6, "the floor's share %.7g (got %r)"
          % (want, r1["floor_share"]["value"]))
    check(r1["steps"]["value"] == 5000, "steps 5000 (got %r)" % r1["steps"]["value"])
    check(r2["max_dphi_bed_from_finest"]["value"] == 0.0,
          "a surface cell's phi is not the bed's (got %r)" % r2["max_dphi_bed_from_finest"]["value"])
    check(close(r2["max_dcolumn_mass_from_finest"]["value"], col, 1e-6), "the surface cell counts in its column "
          "(got %r)" % r2["max_dcolumn_mass_from_finest"]["value"])
    check(fin["bed_arrival"]["value"] is not None and close(fin["bed_arrival"]["value"], 2.05, 1e-6),
          "bed arrival 2.05 s as filling2d.py finds it (got %r)" % fin["bed_arrival"]["value"])
    with open(os.path.join(out, "steps2d.md")) as fh:
        md = fh.read()
    check(all(("| %s |" % n) in md for n in ("syn_r0.01", "syn_r0.1", "syn_r1")), "steps2d.md has a row per run")
    # bad inputs
    empty = os.path.join(work, "empty")
    os.makedirs(empty)
    rc, _, err = steps2d(src, ["--runs", empty, "-o", os.path.join(work, "out_empty")])
    check(rc == 3 and len(err.strip().splitlines()) == 1, "no runs: status 3, one line (got %d: %r)" % (rc, err))
    bad = os.path.join(work, "bad")
    os.makedirs(bad)
    shutil.copy(base, os.path.join(bad, "syn_r0.01.h5"))
    with h5py.File(os.path.join(bad, "syn_r0.01.h5"), "r+") as f:
        del f["szz"]
    rc, _, err = steps2d(src, ["--runs", bad, "-o", os.path.join(work, "out_bad")])
    check(rc == 2 and len(err.strip().splitlines()) == 1 and "szz" in err,
          "a run without /szz: status 2, one line naming szz (got %d: %r)" % (rc, err))
    check(not os.path.exists(os.path.join(work, "out_bad", "steps2d.json")), "no steps2d.json on bad input")
    # runs of one set that end at different times: not comparable
    mixed = os.path.join(work, "mixed")
    os.makedirs(mixed)
    shutil.copy(base, os.path.join(mixed, "syn_r0.01.h5"))
    shutil.copy(base, os.path.join(mixed, "syn_r0.1.h5"))
    with h5py.File(os.path.join(mixed, "syn_r0.1.h5"), "r+") as f:
        f["t"][-1] = 3.99
    rc, _, err = steps2d(src, ["--runs", mixed, "-o", os.path.join(work, "out_mixed")])
    check(rc == 2 and len(err.strip().splitlines()) == 1 and "syn_r0.1.h5" in err and "t = 3.99 s" in err,
          "a run ending at another time: status 2, one line naming it (got %d: %r)" % (rc, err))
    check(not os.path.exists(os.path.join(work, "out_mixed", "steps2d.json")), "no steps2d.json for a mixed set")
    print("steps2d_test: %d failure(s)" % len(failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
