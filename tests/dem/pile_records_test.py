#!/usr/bin/python3
"""pile_records_test.py: the sand-pile run records (pile_record.sh, pile_record.py)
and pile_analysis.sh on them.

    tests/dem/pile_records_test.py EKMCOMPARE WORKDIR   (EKMSCENARIO= names the ekmscenario binary)

No DEM engine: six finished runs written by hand in the layout of
scripts/dem/ensemble.sh (WORKDIR/runs/plain/seed<k>/sandpile/lammps-ref/<point>/:
run.json status ok, vars.txt, screen.txt with the deck's EKMDEM lines,
atoms.dump with the contract's columns, two frames), the reference plate
(130 d box, 102 d plate of floor grains on the lattice x = (i + 1/2) d, 4
across y): a wedge pile h(x) = 20 d (1 - |x - c| / 51 d), one surface grain
per 2 d bin over a bottom layer; each floor grain carries fz = -p(x) d^2 (1 + 0.1 noise) with
p ~ h (1 + A s / 51 d); the pile grains' masses make the floor force equal
their weight, so check_run.sh --sandpile passes. Points source8 (the
hopper: A = 3, a dip of 0.25) and source102 (the sieve: A = 0, no dip),
members 1-3 each.

  1. pile_record.sh records each run (exit 0) with its map.h5, under 60 kB each; run again,
     it keeps them (exit 0, record.json unchanged); a run of the plain law
     recorded as rolling is refused (2, one line naming vars.txt) and
     leaves nothing behind;
  2. pile_analysis.sh on the records (exit 0): the group file of the
     hopper holds p_base_runs [3][65] equal to `ekmcompare base --last 1`
     over the three dumps, and the same x, p_base, dx, centre; stats-ref.json
     has both groups with 3 runs, the hopper's D_fit within 0.05 of 0.245
     (the noiseless value of this dip) and above the sieve's by 3 SE, the
     local weight from the records (the sieve's p(0) / rho_b g h(0) within
     0.1 of 1, floor counts aligned); summary-plain-ref.json has the rows
     of pile_summary.py --runs over the same runs;
  3. a record recovered from a group file (pile_record.py recover, an
     older group file of member 4's hopper run and its summary table): the
     hopper group gets 4 runs, no local weight (local_weight_missing) and
     its map over the 3 records that have a map.h5 (map.partial says so);
     a summary row that does not match the profile is refused (2);
  4. bad records: pile_analysis.sh stops with one line on stderr naming the
     file and the documented status, and leaves the outputs as they were:
     record.json not JSON (2), a record in another member's place (2),
     base.h5 missing (3), a record whose vars.txt differs from its group's
     (2); a ROOT holding runs rather than records (2).
Exit 0 if every check holds, 1 otherwise (one line per failed check).
"""
import hashlib
import json
import os
import shutil
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DEM = os.path.join(ROOT, "scripts", "dem")
D, G = 0.002, 9.81
LX, LY, PLATE = 130 * D, 4 * D, 102 * D
H = 20 * D
COLS = ("id type x y z vx vy vz radius mass omegax omegay omegaz "
        "c_sa[1] c_sa[2] c_sa[3] c_sa[4] c_sa[5] c_sa[6] fx fy fz")
failures = []


def check(ok, what):
    print(("ok: " if ok else "FAILED: ") + what)
    if not ok:
        failures.append(what)


def row(aid, typ, x, y, z, mass, fz, radius=0.5 * D, sa=(0, 0, 0, 0, 0, 0)):
    return ("%d %d %.9g %.9g %.9g 0 0 0 %.9g %.9g 0 0 0 %.9g %.9g %.9g %.9g %.9g %.9g 0 0 %.9g"
            % ((aid, typ, x, y, z, radius, mass) + tuple(sa) + (fz,)))


def write_run(path, amp, seed, rng, pile=None):
    """A finished run; pile(): the pile grains [(x, y, z, radius, c_sa 6)] instead of
    the surface grains and the bottom layer (tests/dem/pile_maps_test.py)."""
    os.makedirs(path, exist_ok=True)
    rows, aid = [], 0
    load = 0.0
    for i in range(int(round((LX - PLATE) / 2 / D)), int(round((LX + PLATE) / 2 / D))):
        x = (i + 0.5) * D
        u = abs(x - LX / 2) / (PLATE / 2)
        p = 1500.0 * G * H * max(1 - u, 0.0) * (1 + amp * u)
        for j in range(4):
            aid += 1
            f = p * D * D * (1 + 0.1 * rng.standard_normal())
            load += f
            rows.append(row(aid, 2, x, (j + 0.5) * D, -0.5 * D, 1e-5, -f))
    # the surface: one grain per 2 d bin whose top is h(x); and a bottom
    # layer, one grain per 2 d bin on the floor (check_run.sh: a floor
    # grain no pile grain touches carries no force)
    if pile is None:
        tops = [b for b in (np.arange(7, 58) * 2 * D + D) if H * (1 - abs(b - LX / 2) / (PLATE / 2)) > D]
        low = np.arange(7, 58) * 2 * D + D
        grains = [(x, 0.5 * LY, H * (1 - abs(x - LX / 2) / (PLATE / 2)) - 0.5 * D, 0.5 * D, (0,) * 6) for x in tops]
        grains += [(x, 0.5 * LY, 0.5 * D, 0.5 * D, (0,) * 6) for x in low]
    else:
        grains = pile()
    m = load / G / len(grains)  # the floor carries the pile's weight exactly
    for x, y, z, r, sa in grains:
        aid += 1
        rows.append(row(aid, 1, x, y, z, m, 0.0, r, sa))
    bins = grains
    with open(os.path.join(path, "atoms.dump"), "w") as f:
        for s in (410000, 420000):
            f.write("ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ATOMS\n%d\nITEM: BOX BOUNDS pp pp fm\n" % (s, len(rows)))
            f.write("0 %.9g\n0 %.9g\n%.9g %.9g\n" % (LX, LY, -1.5 * D, 40 * D))
            f.write("ITEM: ATOMS " + COLS + "\n" + "\n".join(rows) + "\n")
    mass = m * len(bins)
    with open(os.path.join(path, "screen.txt"), "w") as f:
        f.write("EKMDEM_MASS target %.9g inserted %.9g final %.9g ninserted %d ntarget %d ke_per_mass 0\n"
                % (mass, mass, mass, len(bins), len(bins)))
        f.write("EKMDEM_PILE floor_fz 0 weight %.9g sunk 0\n" % (mass * G))
        f.write("EKMDEM_DONE natoms %d steps 420000\n" % aid)
    width = 8 if amp else 102
    with open(os.path.join(path, "vars.txt"), "w") as f:
        f.write("d = %g\ndt = 1e-5\nseed = %d\ng = %g\nlx = %g\nlz = %g\nlp = %g\nly = %g\nmu_r = 0\nt_end = 4.2\n"
                "source_width = %d\n" % (D, seed, G, LX, 40 * D, PLATE, LY, width))
    with open(os.path.join(path, "run.json"), "w") as f:
        json.dump({"scenario": "sandpile", "engine": "lammps", "size": "ref", "point": "source%d" % width,
                   "scenario_file": "scenarios/sandpile.ini", "status": "ok", "wall_time_s": 1.0,
                   "particles": aid}, f, indent=1)
    for name in ("deck.in", "log.txt", "pairs.dump"):
        with open(os.path.join(path, name), "w") as f:
            f.write("synthetic\n")
    return path


def sh(*cmd):
    r = subprocess.run(list(cmd), capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


def digest(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def outputs(out):
    return {f: digest(os.path.join(out, f)) for f in sorted(os.listdir(out))}


def main():
    if len(sys.argv) != 3:
        print("usage: pile_records_test.py EKMCOMPARE WORKDIR", file=sys.stderr)
        return 2
    ekmcompare, work = sys.argv[1], sys.argv[2]
    import h5py
    shutil.rmtree(work, ignore_errors=True)
    os.environ["EKMCOMPARE"] = ekmcompare
    rng = np.random.default_rng(34)
    runs = os.path.join(work, "runs", "plain")
    recs = os.path.join(work, "records")
    dirs = {}
    for k in (1, 2, 3, 4):
        for amp, pt in ((3.0, "source8"), (0.0, "source102")):
            dirs[(k, pt)] = write_run(os.path.join(runs, "seed%d" % k, "sandpile", "lammps-ref", pt), amp,
                                      15485863 + k, rng)
    # 1. recording
    first = [dirs[(k, pt)] for k in (1, 2, 3) for pt in ("source8", "source102")]
    rc, so, se = sh(os.path.join(DEM, "pile_record.sh"), "-R", recs, "-l", "plain", *first)
    rec1 = os.path.join(recs, "plain", "lammps-ref", "source8", "seed1")
    size = sum(os.path.getsize(os.path.join(rec1, f)) for f in os.listdir(rec1))
    check(rc == 0 and len([1 for d in os.listdir(os.path.join(recs, "plain", "lammps-ref")) for _ in
                           os.listdir(os.path.join(recs, "plain", "lammps-ref", d))]) == 6 and size < 60000
          and os.path.exists(os.path.join(rec1, "map.h5")) and not os.path.exists(os.path.join(rec1, "cg.h5")),
          "1. pile_record.sh records 6 runs with their maps: exit %d, a record %d bytes (< 60000)\n%s" % (rc, size, se))
    before = digest(os.path.join(rec1, "record.json"))
    rc, so, se = sh(os.path.join(DEM, "pile_record.sh"), "-R", recs, "-l", "plain", dirs[(1, "source8")])
    check(rc == 0 and "kept" in so and digest(os.path.join(rec1, "record.json")) == before,
          "1. recorded again: kept, unchanged (exit %d)\n%s%s" % (rc, so, se))
    rc, so, se = sh(os.path.join(DEM, "pile_record.sh"), "-R", os.path.join(work, "wrong"), "-l", "rolling",
                    dirs[(1, "source8")])
    left = [f for _, _, fs in os.walk(os.path.join(work, "wrong")) for f in fs]
    check(rc == 2 and len(se.strip().splitlines()) == 1 and "vars.txt: mu_r = 0" in se and not left,
          "1. a plain run recorded as rolling: exit %d (2), one line naming vars.txt, nothing left (%s)\n%s"
          % (rc, left, se))
    # 2. the analysis
    out = os.path.join(work, "out")
    rc, so, se = sh(os.path.join(DEM, "pile_analysis.sh"), "-o", out, recs, "ref")
    check(rc == 0, "2. pile_analysis.sh on the records: exit %d (0)\n%s" % (rc, se))
    direct = os.path.join(work, "direct.h5")
    sh(ekmcompare, "base", "--last", "1", "--quiet", "-o", direct, *[dirs[(k, "source8")] + "/atoms.dump"
                                                                      for k in (1, 2, 3)])
    try:
        with h5py.File(os.path.join(out, "base-plain-lammps-hopper-ref.h5")) as a, h5py.File(direct) as b:
            same = (a["p_base_runs"].shape == (3, 65)
                    and np.array_equal(a["p_base_runs"][...], b["p_base_runs"][...], equal_nan=True)
                    and np.allclose(a["p_base"][...], b["p_base"][...], rtol=1e-12, equal_nan=True)
                    and np.array_equal(a["x"][...], b["x"][...])
                    and all(a.attrs[k] == b.attrs[k] for k in ("dx", "centre", "y_period", "lo", "hi", "runs"))
                    and "h_runs" in a)
    except (OSError, KeyError) as e:
        same = "%s" % e
    check(same is True, "2. the hopper's group file is ekmcompare base over the three dumps (%s)" % same)
    try:
        st = json.load(open(os.path.join(out, "stats-ref.json")))
        hop, sie = st["groups"]["lammps/plain/hopper"], st["groups"]["lammps/plain/sieve"]
        dh, ds = hop["D_fit"], sie["D_fit"]
        ratio = sie["centre_over_local_weight"]["value"]
        ok = (hop["runs"] == 3 and sie["runs"] == 3 and abs(dh["value"] - 0.245) < 0.05
              and dh["value"] - ds["value"] > 3 * np.hypot(dh["se"], ds["se"]) and abs(ratio - 1) < 0.1
              and sie["floor_count_max_deviation"] == 0 and len(st["comparisons"]) == 1)
        got = "D_fit %.4f +- %.4f and %.4f +- %.4f, p(0)/W(0) %.3f" % (dh["value"], dh["se"], ds["value"], ds["se"],
                                                                     ratio)
    except (OSError, ValueError, KeyError) as e:
        ok, got = False, "stats-ref.json: %s" % e
    check(ok, "2. stats from the records: %s" % got)
    ref = os.path.join(work, "summary-direct.json")
    sh("/usr/bin/python3", "-B", os.path.join(DEM, "pile_summary.py"), "--runs", "-o", ref, *first)
    try:
        a = json.load(open(os.path.join(out, "summary-plain-ref.json")))
        b = json.load(open(ref))
        strip = [{k: v for k, v in r.items() if k != "run"} for r in a["runs"]]
        ok = (sorted(strip, key=lambda r: (r["point"], r["seed"]))
              == sorted(({k: v for k, v in r.items() if k != "run"} for r in b["runs"]),
                        key=lambda r: (r["point"], r["seed"])) and a["groups"] == b["groups"])
    except (OSError, ValueError, KeyError) as e:
        ok = "%s" % e
    check(ok is True, "2. summary-plain-ref.json: the rows and groups of pile_summary.py --runs (%s)" % ok)
    # 3. a record recovered from an older group file
    old = os.path.join(work, "old")
    oldrun = os.path.join(old, "runs", "pile", "plain", "seed4", "sandpile", "lammps-ref", "source8")
    shutil.copytree(dirs[(4, "source8")], oldrun)
    oldbase = os.path.join(old, "base-plain-lammps-hopper-ref.h5")
    sh(ekmcompare, "base", "--last", "1", "--quiet", "-o", oldbase, os.path.join(oldrun, "atoms.dump"))
    oldsum = os.path.join(old, "summary-plain-ref.json")
    sh("/usr/bin/python3", "-B", os.path.join(DEM, "pile_summary.py"), "--runs", "-o", oldsum,
       os.path.join(old, "runs", "pile", "plain", "seed4", "sandpile", "lammps-ref", "source8"))
    # pile_summary.py --runs roots a single run at itself: the earlier tables' root was the law's directory
    doc = json.load(open(oldsum))
    doc["root"] = os.path.join(old, "runs", "pile", "plain")
    doc["runs"][0]["run"] = "seed4/sandpile/lammps-ref/source8"
    bad = dict(doc, runs=[dict(doc["runs"][0], base_force=doc["runs"][0]["base_force"] * 1.01)])
    json.dump(bad, open(oldsum, "w"))
    rc, so, se = sh("/usr/bin/python3", "-B", os.path.join(DEM, "pile_record.py"), "recover", "-R", recs,
                    "--summary", oldsum, oldbase)
    check(rc == 2 and len(se.strip().splitlines()) == 1 and oldsum in se and "does not match" in se
          and not os.path.exists(os.path.join(recs, "plain", "lammps-ref", "source8", "seed4")),
          "3. recover: a summary row that does not match the profile: exit %d (2), one line, no record\n%s" % (rc, se))
    json.dump(doc, open(oldsum, "w"))
    rc, so, se = sh("/usr/bin/python3", "-B", os.path.join(DEM, "pile_record.py"), "recover", "-R", recs,
                    "--summary", oldsum, oldbase)
    rc2, so2, se2 = sh(os.path.join(DEM, "pile_analysis.sh"), "-o", out, recs, "ref")
    try:
        hop = json.load(open(os.path.join(out, "stats-ref.json")))["groups"]["lammps/plain/hopper"]
        ok = (rc == 0 and rc2 == 0 and hop["runs"] == 4 and "local_weight_missing" in hop and "rho_b" not in hop
              and hop.get("map", {}).get("runs") == 3 and "3 of 4 records" in hop["map"].get("partial", ""))
        got = "%d runs, %s, map %s" % (hop["runs"], "no local weight" if "rho_b" not in hop else "local weight",
                                       json.dumps(hop.get("map", hop.get("map_missing")))[:300])
    except (OSError, ValueError, KeyError) as e:
        ok, got = False, "%s" % e
    check(ok, "3. a recovered record joins its group (exit %d, %d): %s\n%s%s" % (rc, rc2, got, se, se2))
    # 4. bad records: one line naming the file, the status, the outputs untouched
    saved = outputs(out)

    def bad_case(what, setup, undo, code, name):
        setup()
        rc, so, se = sh(os.path.join(DEM, "pile_analysis.sh"), "-o", out, recs, "ref")
        undo()
        lines = se.strip().splitlines()
        check(rc == code and len(lines) == 1 and name in lines[0] and outputs(out) == saved,
              "4. %s: exit %d (%d), one line naming %s, outputs unchanged\n%s" % (what, rc, code, name, se))

    rj = os.path.join(recs, "plain", "lammps-ref", "source102", "seed2", "record.json")
    text = open(rj).read()
    bad_case("record.json not JSON", lambda: open(rj, "w").write(text[:-20]),
             lambda: open(rj, "w").write(text), 2, rj)
    src = os.path.join(recs, "plain", "lammps-ref", "source102", "seed3")
    dst = os.path.join(recs, "plain", "lammps-ref", "source102", "seed7")
    bad_case("a record in member 7's place", lambda: os.rename(src, dst), lambda: os.rename(dst, src), 2,
             os.path.join(dst, "record.json"))
    bh = os.path.join(src, "base.h5")
    bad_case("base.h5 missing", lambda: os.rename(bh, bh + ".away"), lambda: os.rename(bh + ".away", bh), 3, bh)
    vt = os.path.join(src, "vars.txt")
    vtext = open(vt).read()
    bad_case("a record whose t_end differs from its group's", lambda: open(vt, "w").write(vtext.replace("4.2", "3.4")),
             lambda: open(vt, "w").write(vtext), 2, vt)
    # the settling's end may differ (a record made before it has no
    # settle_max, rest_ke): the group still pools
    open(vt, "a").write("settle_max = 8\nrest_ke = 1e-5\n")
    rc, so, se = sh(os.path.join(DEM, "pile_analysis.sh"), "-o", out + "_settle", recs, "ref")
    open(vt, "w").write(vtext)
    check(rc == 0, "4. a record with settle_max and rest_ke pools with records without: exit %d (0)\n%s" % (rc, se))
    rc, so, se = sh(os.path.join(DEM, "pile_analysis.sh"), "-o", out, os.path.join(work, "runs"), "ref")
    check(rc == 2 and len(se.strip().splitlines()) == 1 and "pile_record.sh" in se and outputs(out) == saved,
          "4. a ROOT of runs, not records: exit %d (2), one line\n%s" % (rc, se))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
