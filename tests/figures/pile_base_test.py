#!/usr/bin/python3
"""pile_base_test.py: figures/pile_base.py (the sand piles' base pressure,
DEM ensembles beside EKM piles) on synthetic inputs with known curves,
written under WORK. Python only: no ekm.

    /usr/bin/python3 pile_base_test.py SOURCE_DIR WORK

DEM: a base group file of 3 runs on 8 bins of 2 d (x = 1, 3, ..., 15 d),
run r's profile 100 (bin + 1) + 10 r [Pa]; with --merge 2, bins (0, 1),
(2, 3), ...: mean 100 (2k + 1.5) + 10 [Pa], SE over runs 10 / sqrt(3)
(the runs differ by 10 Pa steps: sd 10); a second file (LIGGGHTS) the
same + 5 Pa. EKM: a 2D run of 3 frames on 12 x 2 cells whose last
frame's lowest row has phi 0.6 in columns 1-10 and 0.01 in 0 and 11, szz
= -(50 + column) [Pa]: the curve is 51..60 Pa in columns 1-10 and empty
beside them. Checks: the CSV holds those numbers to its 9 digits; the
JSON's scores (below, at the check) to 1e-12; a panel per source in their order, the PDF and PNG exist. Bad inputs: a
missing DEM file: status 3, one line naming it; a DEM file without
p_base_runs: status 2; --time with no such output: status 2 naming the
nearest; a malformed --ekm: status 1; nothing written on an error. And
figures/pilemaps.py's command line: a map group beside the EKM run drawn;
a missing group or output time: one line, exit 2, nothing written.
Exit status 77 (skipped) when numpy, h5py or matplotlib is missing.
"""
import csv
import json
import math
import os
import shutil
import subprocess
import sys

try:
    import numpy as np
    import h5py
    import matplotlib  # noqa: F401
except ImportError as e:
    print("skipped: %s" % e)
    sys.exit(77)

src, work = sys.argv[1], sys.argv[2]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
prog = [sys.executable, "-B", os.path.join(src, "figures", "pile_base.py")]
fails = []
D = 0.002


def check(ok, what):
    if not ok:
        fails.append(what)
        print("FAIL: %s" % what, file=sys.stderr)


dem = os.path.join(work, "base.h5")
with h5py.File(dem, "w") as f:
    f["x"] = (np.arange(8) * 2 + 1) * D
    f["p_base_runs"] = np.array([[100.0 * (b + 1) + 10 * r for b in range(8)] for r in range(3)])
dem2 = os.path.join(work, "base2.h5")
with h5py.File(dem2, "w") as f:
    f["x"] = (np.arange(8) * 2 + 1) * D
    f["p_base_runs"] = np.array([[100.0 * (b + 1) + 10 * r + 5 for b in range(8)] for r in range(3)])
ekm = os.path.join(work, "run.h5")
NX = 12
with h5py.File(ekm, "w") as f:
    f["x"] = (np.arange(NX) + 0.5) * D
    f["z"] = (np.arange(2) + 0.5) * D
    f["t"] = np.array([0.0, 0.5, 1.0])
    phi = np.zeros((3, 2, NX))
    phi[-1, 0, 1:11] = 0.6
    phi[-1, 0, [0, 11]] = 0.01
    szz = np.zeros((3, 2, NX))
    szz[-1, 0, :] = -(50.0 + np.arange(NX))
    f["phi"], f["szz"] = phi, szz
    f["phi"].attrs["units"], f["szz"].attrs["units"] = "1", "Pa"
    f.attrs["stats.wall_time_s"] = 1.0

out = os.path.join(work, "fig", "pile_base")
r = subprocess.run(prog + [out, "--dem", "hopper:lammps=" + dem, "--dem", "sieve:liggghts=" + dem,
                           "--dem", "hopper:liggghts=" + dem2, "--ekm", "hopper:full=" + ekm],
                   capture_output=True, text=True)
check(r.returncode == 0, "a good run: exit 0 (%d: %s)" % (r.returncode, r.stderr.strip()))
for ext in ("pdf", "png", "csv", "json"):
    check(os.path.isfile("%s.%s" % (out, ext)) and os.path.getsize("%s.%s" % (out, ext)) > 0, "%s.%s written" % (out, ext))
rows = []
if os.path.isfile(out + ".csv"):
    with open(out + ".csv") as fh:
        rows = list(csv.DictReader(l for l in fh if not l.startswith("#")))
hop = [w for w in rows if w["source"] == "hopper" and w["what"] == "DEM lammps"]
check(len(hop) == 4, "the DEM curve has 4 merged bins (%d)" % len(hop))
for k, w in enumerate(hop):
    check(abs(float(w["x_m"]) - (4 * k + 2) * D) < 1e-12, "merged bin %d at x = %g d" % (k, 4 * k + 2))
    check(abs(float(w["p_Pa"]) - (100 * (2 * k + 1.5) + 10)) < 1e-9, "merged bin %d mean" % k)
    check(abs(float(w["se_Pa"]) - 10 / math.sqrt(3)) < 1e-7, "merged bin %d SE over the runs" % k)  # 9 digits
check(len([w for w in rows if w["source"] == "sieve" and w["what"] == "DEM liggghts"]) == 4, "the sieve panel's curve")
ek = [w for w in rows if w["what"] == "EKM full"]
check(len(ek) == NX and all(w["source"] == "hopper" for w in ek), "the EKM curve: %d cells in the hopper panel" % NX)
for i, w in enumerate(ek):
    if 1 <= i <= NX - 2:
        check(w["p_Pa"] != "" and abs(float(w["p_Pa"]) - (50 + i)) < 1e-9, "EKM cell %d: -szz" % i)
    else:
        check(w["p_Pa"] == "", "EKM cell %d (phi 0.01): empty" % i)


# the scores: the EKM's cells averaged over each 4 d DEM bin ([0, 8) mm:
# cells 0-3, cell 0 empty: left out; [8, 16): cells 4-7, 55.5 Pa; [16, 24):
# cell 11 empty; [24, 32): no cell), so one bin against the DEM's mean 360
# Pa, the jackknife over the three runs' leave-one-out means 365, 360, 355;
# the floor: LIGGGHTS's mean is LAMMPS's + 5 Pa in every bin
def jack(vals):
    n = len(vals)
    m = sum(vals) / n
    return math.sqrt((n - 1) / n * sum((v - m) ** 2 for v in vals))


try:
    with open(out + ".json") as fh:
        sc = json.load(fh)["sources"]
    v = sc["hopper"]["ekm"]["full"]["lammps"]
    check(abs(v["rel_l2"] - (360 - 55.5) / 360) < 1e-12 and v["bins"] == 1 and v["bins_left_out"] == 3,
          "EKM against LAMMPS: rel L2 over the one common bin, 3 left out (%s)" % v)
    check(abs(v["se"] - jack([(m - 55.5) / m for m in (365.0, 360.0, 355.0)])) < 1e-12,
          "EKM against LAMMPS: the jackknife SE (%s)" % v["se"])
    lam = np.array([100 * (2 * k + 1.5) + 10 for k in range(4)])
    fl = sc["hopper"]["floor"]
    check(abs(fl["rel_l2"] - 5 * 2 / np.linalg.norm(lam)) < 1e-12 and fl["bins"] == 4,
          "the engine floor: 5 Pa in 4 bins over LAMMPS's norm (%s)" % fl)
    check(sc["sieve"]["floor"] is None and sc["sieve"]["ekm"] == {}, "the sieve panel: no floor, no EKM")
except (OSError, ValueError, KeyError, TypeError) as e:
    check(False, "%s.json: %s" % (out, e))


def bad(args, status, text, what):
    o = os.path.join(work, "bad", "x")
    r = subprocess.run(prog + [o] + args, capture_output=True, text=True)
    lines = r.stderr.strip().splitlines()
    check(r.returncode == status, "%s: exit %d (got %d: %s)" % (what, status, r.returncode, r.stderr.strip()))
    check(status == 1 or (len(lines) == 1 and text in lines[0]), "%s: one line with '%s' (%s)" % (what, text, lines))
    check(not any(os.path.exists(o + e) for e in (".pdf", ".png", ".csv", ".json")), "%s: nothing written" % what)


bad(["--dem", "hopper:lammps=" + os.path.join(work, "none.h5")], 3, "none.h5: missing", "missing DEM file")
nop = os.path.join(work, "nop.h5")
with h5py.File(nop, "w") as f:
    f["x"] = np.arange(4.0)
bad(["--dem", "hopper:lammps=" + nop], 2, "/p_base_runs: missing", "DEM file without runs")
bad(["--dem", "hopper:lammps=" + dem, "--ekm", "hopper:full=" + ekm, "--time", "0.7"], 2,
    "no output at t = 0.7 s (nearest 0.5 s)", "no EKM output at --time")
bad(["--dem", "hopper:lammps=" + dem, "--ekm", "full=" + ekm], 1, "", "malformed --ekm")

# figures/pilemaps.py's command line (the sand pile's maps at ref size):
# a map group beside the EKM run at t = 1 s draws both files; a group the
# map file lacks and an output time the run lacks: one line, exit 2
maps = os.path.join(work, "maps.h5")
with h5py.File(maps, "w") as f:
    g = f.create_group("lammps/plain/hopper")
    g["x"] = (np.arange(NX) + 0.5) * D
    g["z"] = (np.arange(2) + 0.5) * D
    g["phi"] = np.full((2, NX), 0.6)
    g["szz"] = np.full((2, NX), 300.0)
pm = [sys.executable, "-B", os.path.join(src, "figures", "pilemaps.py")]
o = os.path.join(work, "maps", "maps_hopper")
r = subprocess.run(pm + [o, "--map", "lammps=%s:/lammps/plain/hopper" % maps, "--ekm", "full=" + ekm, "--time", "1"],
                   capture_output=True, text=True)
check(r.returncode == 0 and all(os.path.getsize(o + e) > 0 for e in (".pdf", ".png") if os.path.exists(o + e))
      and os.path.exists(o + ".png"), "pilemaps.py: a map group and an EKM run drawn (%d: %s)" % (r.returncode, r.stderr.strip()))
for args, text, what in (
        (["--map", "lammps=%s:/lammps/plain/sieve" % maps], "group /lammps/plain/sieve: missing", "a missing map group"),
        (["--map", "lammps=%s:/lammps/plain/hopper" % maps, "--ekm", "full=" + ekm, "--time", "0.7"],
         "no output at t = 0.7 s (nearest 0.5 s", "an EKM time the run lacks")):
    ob = os.path.join(work, "maps", "bad")
    r = subprocess.run(pm + [ob] + args, capture_output=True, text=True)
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 2 and len(lines) == 1 and text in lines[0] and not os.path.exists(ob + ".png"),
          "pilemaps.py, %s: exit 2, one line with '%s' (%d: %s)" % (what, text, r.returncode, lines))


print("pile_base_test: %s" % ("%d failure(s)" % len(fails) if fails else "all passed"))
sys.exit(1 if fails else 0)
