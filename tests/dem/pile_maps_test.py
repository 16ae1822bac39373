#!/usr/bin/python3
"""pile_maps_test.py: the density and stress maps of the sand-pile run records
(pile_record.sh's map.h5, pile_map.py, pile_stats.py through pile_analysis.sh).

    tests/dem/pile_maps_test.py EKMCOMPARE WORKDIR   (EKMSCENARIO= names the ekmscenario binary)

No DEM engine: finished runs written as in pile_records_test.py (the
reference plate, 130 d box, 102 d plate), but the pile is filled: a wedge
h(x) = 20 d (1 - |x - c| / 51 d) of grains on a lattice of spacing d in x
and z (centres (i + 1/2) d, (k + 1/2) d, a grain where its top is below
h(x), and the bottom row everywhere), 4 across y; each grain jittered by up
to 0.15 d in x and z, its radius d/2 (1 + u), u uniform in +-0.05 (so phi =
pi/6 (1 + 0.05^2) without a deficit). Per-atom stress c_sa = -sigma d^3,
sigma_zz = rho g (h(x) - z), sigma_xx = K sigma_zz (K with 10% noise per
grain), sigma_xz = -sign(x - c) 0.2 sigma_zz for |x - c| > 8 d.

  hopper (source8, 4 runs): the grains with |x - c| < 8 d have their
    radius scaled by 0.95^(1/3): phi under the apex is lower by
    pi/6 (1.0025) 0.05 = 0.02624; K = 2 there (arching), 0.5 elsewhere;
  sieve (source102, 4 runs): no deficit, K = 0.5 everywhere.

  1. pile_record.sh records the 8 runs with map.h5 (exit 0);
  2. pile_analysis.sh (exit 0): the hopper's phi_apex_minus_flanks is the
     deficit -0.02624 within 3 of its SEs over runs (the SE below 0.005: the
     test can tell), less dense at 3 SE; the sieve's is consistent with 0
     (|value| < 3 SE); both have se_map; the hopper's K_apex is 2 within
     0.05 and arches (true), theta under the apex 90 deg within 1, the
     sieve's K_apex 0.5 within 0.05 and arches false, theta 0 within 1; the
     lean on the flanks 19.3 deg (the synthetic sigma_xz) within 2 in both;
     maps-ref.h5 holds both groups' mean maps with units;
  3. bad maps: map.h5 not HDF5 (2), map.h5 without czz (2), a map on
     another grid than its group's (2): pile_analysis.sh stops with one line
     naming that map.h5 and leaves the outputs as they were.
Exit 0 if every check holds, 1 otherwise.
"""
import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pile_records_test as prt  # noqa: E402  (the run writer)

D, LX, LY, PLATE, H, G = prt.D, prt.LX, prt.LY, prt.PLATE, prt.H, prt.G
C = LX / 2
SHRINK = 0.95 ** (1.0 / 3.0)
DEFICIT = -math.pi / 6 * (1 + 0.05 ** 2) * (1 - 0.95)
LEAN = -0.5 * math.degrees(math.atan2(2 * -0.2, 1 - 0.5))
failures = []


def check(ok, what):
    print(("ok: " if ok else "FAILED: ") + what)
    if not ok:
        failures.append(what)


def filled(rng, deficit):
    def grains():
        out = []
        for i in range(int(round((LX - PLATE) / 2 / D)), int(round((LX + PLATE) / 2 / D))):
            x0 = (i + 0.5) * D
            s0 = abs(x0 - C)
            h = H * (1 - s0 / (PLATE / 2))
            k = 0
            while k == 0 or (k + 1) * D <= h:
                for j in range(4):
                    x = x0 + rng.uniform(-0.15, 0.15) * D
                    z = (k + 0.5) * D + rng.uniform(-0.15, 0.15) * D
                    r = 0.5 * D * (1 + rng.uniform(-0.05, 0.05))
                    inner = s0 < 8 * D
                    if deficit and inner:
                        r *= SHRINK
                    szz = 1500.0 * G * max(h - z, 0.0)
                    K = (2.0 if deficit and inner else 0.5) * (1 + 0.1 * rng.standard_normal())
                    sxz = 0.0 if inner else -np.sign(x0 - C) * 0.2 * szz
                    v = D ** 3
                    out.append((x, (j + 0.5) * D, z, r, (-K * szz * v, -0.5 * szz * v, -szz * v, 0.0, -sxz * v, 0.0)))
                k += 1
        return out
    return grains


def sh(*cmd):
    r = subprocess.run(list(cmd), capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


def main():
    if len(sys.argv) != 3:
        print("usage: pile_maps_test.py EKMCOMPARE WORKDIR", file=sys.stderr)
        return 2
    ekmcompare, work = sys.argv[1], sys.argv[2]
    import h5py
    shutil.rmtree(work, ignore_errors=True)
    os.environ["EKMCOMPARE"] = ekmcompare
    rng = np.random.default_rng(3434)
    runs = os.path.join(work, "runs", "plain")
    recs = os.path.join(work, "records")
    dirs = []
    for k in (1, 2, 3, 4):
        for amp, pt in ((3.0, "source8"), (0.0, "source102")):
            dirs.append(prt.write_run(os.path.join(runs, "seed%d" % k, "sandpile", "lammps-ref", pt), amp,
                                      15485863 + k, rng, pile=filled(rng, amp > 0)))
    # 1. recording
    rc, so, se = sh(os.path.join(prt.DEM, "pile_record.sh"), "-R", recs, "-l", "plain", *dirs)
    maps = [os.path.join(recs, "plain", "lammps-ref", pt, "seed%d" % k, "map.h5")
            for k in (1, 2, 3, 4) for pt in ("source8", "source102")]
    check(rc == 0 and all(os.path.exists(m) for m in maps),
          "1. pile_record.sh records 8 runs with map.h5: exit %d (%d kB a map)\n%s"
          % (rc, os.path.getsize(maps[0]) // 1000 if os.path.exists(maps[0]) else -1, se))
    # 2. the analysis
    out = os.path.join(work, "out")
    rc, so, se = sh(os.path.join(prt.DEM, "pile_analysis.sh"), "-o", out, recs, "ref")
    check(rc == 0, "2. pile_analysis.sh: exit %d (0)\n%s" % (rc, se))
    try:
        st = json.load(open(os.path.join(out, "stats-ref.json")))
        hop, sie = st["groups"]["lammps/plain/hopper"]["map"], st["groups"]["lammps/plain/sieve"]["map"]
        dh, ds = hop["phi_apex_minus_flanks"], sie["phi_apex_minus_flanks"]
        check(abs(dh["value"] - DEFICIT) < 3 * dh["se_runs"] and dh["se_runs"] < 0.005
              and dh["less_dense_under_apex_at_3se"] and dh["se_map"] > 0 and len(dh["per_run"]) == 4,
              "2. hopper: phi apex - flanks %.5f +- %.5f (runs) +- %.5f (maps), expected %.5f"
              % (dh["value"], dh["se_runs"], dh["se_map"], DEFICIT))
        check(abs(ds["value"]) < 3 * ds["se_runs"] and ds["se_runs"] < 0.005
              and not ds["less_dense_under_apex_at_3se"] and ds["se_map"] > 0,
              "2. sieve: phi apex - flanks %.5f +- %.5f (runs) +- %.5f (maps), expected 0"
              % (ds["value"], ds["se_runs"], ds["se_map"]))
        ah, as_ = hop["arch"], sie["arch"]
        check(abs(ah["K_apex"]["value"] - 2) < 0.05 and ah["arches"] is True and abs(ah["theta_apex_deg"] - 90) < 1
              and abs(ah["lean_flanks_deg"]["value"] - LEAN) < 2,
              "2. hopper: K_apex %.4f +- %.4f, arches %s, theta %.2f deg, lean %.2f deg (expected 2, true, 90, %.2f)"
              % (ah["K_apex"]["value"], ah["K_apex"]["se_runs"], ah["arches"], ah["theta_apex_deg"],
                 ah["lean_flanks_deg"]["value"], LEAN))
        check(abs(as_["K_apex"]["value"] - 0.5) < 0.05 and as_["arches"] is False and as_["theta_apex_deg"] < 1
              and abs(as_["lean_flanks_deg"]["value"] - LEAN) < 2,
              "2. sieve: K_apex %.4f +- %.4f, arches %s, theta %.2f deg, lean %.2f deg (expected 0.5, false, 0, %.2f)"
              % (as_["K_apex"]["value"], as_["K_apex"]["se_runs"], as_["arches"], as_["theta_apex_deg"],
                 as_["lean_flanks_deg"]["value"], LEAN))
    except (OSError, ValueError, KeyError, TypeError) as e:
        check(False, "2. stats-ref.json map keys: %r" % e)
    try:
        with h5py.File(os.path.join(out, "maps-ref.h5"), "r") as f:
            ok = all(g in f and f[g]["phi"].shape == (20, 65) and f[g]["phi"].attrs["units"] == "1"
                     and f[g]["szz"].attrs["units"] == "Pa" and f[g]["theta"].attrs["units"] == "deg"
                     for g in ("lammps/plain/hopper", "lammps/plain/sieve"))
    except (OSError, KeyError) as e:
        ok = "%r" % e
    check(ok is True, "2. maps-ref.h5: both groups' mean maps [20][65] with units (%s)" % ok)
    # 3. bad maps
    saved = prt.outputs(out)

    def bad_case(what, setup, code, name):
        keep = name + ".keep"
        shutil.copyfile(name, keep)
        setup()
        rc, so, se = sh(os.path.join(prt.DEM, "pile_analysis.sh"), "-o", out, recs, "ref")
        os.replace(keep, name)
        lines = se.strip().splitlines()
        check(rc == code and len(lines) == 1 and name in lines[0] and prt.outputs(out) == saved,
              "3. %s: exit %d (%d), one line naming %s, outputs unchanged\n%s" % (what, rc, code, name, se))

    m = maps[3]
    bad_case("map.h5 not HDF5", lambda: open(m, "w").write("not a map\n"), 2, m)

    def drop():
        with h5py.File(m, "a") as f:
            del f["czz"]
    bad_case("map.h5 without czz", drop, 2, m)

    def regrid():
        with h5py.File(m, "a") as f:
            z = f["z"][...]
            for k in ("z", "phi", "cxx", "czz", "cxz"):
                a = f[k][...]
                attrs = dict(f[k].attrs)
                del f[k]
                ds = f.create_dataset(k, data=a[:-1] if k != "z" else z[:-1])
                for ak, av in attrs.items():
                    ds.attrs[ak] = av
    bad_case("a map on another grid than its group's", regrid, 2, m)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
