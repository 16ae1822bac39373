#!/usr/bin/python3
"""pile_summary.py: the scalars of finished sand-pile runs, from their dumps.

    scripts/dem/pile_summary.py RUN_DIR...                 one JSON object per run
    scripts/dem/pile_summary.py --ensemble ROOT -o OUT     the ensemble table

A RUN_DIR is a finished case of scripts/dem/run.sh sandpile (run.json,
vars.txt, atoms.dump). From the last frame of atoms.dump (the pile at rest)
and the dump contract of docs/dem.md "Sand pile":
  weight         g * (mass of the pile grains, type 1, on the plate: z > 0
                 and |x - xmid| < lp/2, xmid the box's middle) [N]
  base_force     -(sum of fz over the floor grains, type 2) [N]
  base_over_weight
  angle_left, angle_right, angle   pile angle [deg]: a straight line fitted
                 to the surface height h(x) of each flank (h: the top
                 z + radius of the grains in 2 d wide x bins; the bins whose
                 h is between 0.2 and 0.8 of the pile's height H)
  height         H, the largest h [m]
  toe_left, toe_right  the pile's extent [m]: the outer edges of the run of
                 2 d bins about the centre whose h is at least d
  toe_margin     distance from the pile's extent to the nearer end of the
                 floor (x = 0 or lx) [m]
  strays         pile grains outside that extent (bounced off the floor)
  p_centre_over_max  base pressure p(x) = -(sum fz of the floor grains in
                 an x bin) / (bin width * box y period), bins of 4 d centred
                 on the pile's centre of mass, folded about it: p of the
                 central bin over the largest p
--ensemble ROOT: every ROOT/seed<k>/sandpile/<engine>-<size>/<point>/ that
finished (status ok), summarised (--runs -o OUT RUN_DIR...: the runs given); OUT gets the per-run rows and, per engine,
size and point, the mean and standard error over the seeds (SE = sd/sqrt(n)).
Exit status: 0 ok, 1 usage, 2 a dump without the contract's columns, 3 a
file missing.
"""
import glob
import json
import math
import os
import sys

import pile_dump  # scripts/dem: the dump reader shared with pile_stats.py


def fail(code, msg):
    print("pile_summary: " + msg, file=sys.stderr)
    sys.exit(code)


def vars_of(run):
    try:
        return pile_dump.read_vars(run)
    except pile_dump.DumpError as e:
        fail(e.code, str(e))


def flank_angle(xs, hs, height):
    pts = [(x, h) for x, h in zip(xs, hs) if 0.2 * height <= h <= 0.8 * height]
    if len(pts) < 3:
        return None
    n = len(pts)
    mx = sum(p[0] for p in pts) / n
    mh = sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    sxh = sum((p[0] - mx) * (p[1] - mh) for p in pts)
    return math.degrees(math.atan(abs(sxh / sxx)))


def summarise(run):
    for f in ("run.json", "vars.txt", "atoms.dump"):
        if not os.path.exists(os.path.join(run, f)):
            fail(3, "%s: no %s" % (run, f))
    rj = json.load(open(os.path.join(run, "run.json")))
    v = vars_of(run)
    try:
        step, bx, ly, cols, rows = pile_dump.last_frame(os.path.join(run, "atoms.dump"))
    except pile_dump.DumpError as e:
        fail(e.code, str(e))
    for c in ("type", "x", "z", "radius", "mass", "fz"):
        if c not in cols:
            fail(2, "%s/atoms.dump: no column %s (docs/dem.md 'Sand pile')" % (run, c))
    ic = {c: cols.index(c) for c in cols}
    d, g, lx = v["d"], v["g"], bx[1] - bx[0]
    # the pile: grains on the plate (centre above its top and within its
    # width lp about the box's middle; one sliding off its edge or falling
    # to the deck's sink is not part of it; without lp the whole box)
    xmid, half = 0.5 * (bx[0] + bx[1]), pile_dump.plate_half_width(run, lx)
    grains = [r for r in rows if r[ic["type"]] == "1"
              and pile_dump.on_plate(float(r[ic["x"]]), float(r[ic["z"]]), xmid, half)]
    floor = [r for r in rows if r[ic["type"]] == "2"]
    mass = sum(float(r[ic["mass"]]) for r in grains)
    if not grains or not mass > 0:
        fail(2, "%s/atoms.dump: the last frame has no pile grains (type 1)" % run)
    xc = sum(float(r[ic["mass"]]) * float(r[ic["x"]]) for r in grains) / mass
    base = -sum(float(r[ic["fz"]]) for r in floor)
    # surface height in 2 d bins
    w = 2 * d
    top = {}
    for r in grains:
        b = math.floor((float(r[ic["x"]]) - xc) / w + 0.5)
        top[b] = max(top.get(b, 0.0), float(r[ic["z"]]) + float(r[ic["radius"]]))
    height = max(top.values())
    left = sorted(b for b in top if b < 0)
    right = sorted(b for b in top if b > 0)
    al = flank_angle([b * w for b in left], [top[b] for b in left], height)
    ar = flank_angle([b * w for b in right], [top[b] for b in right], height)
    lo = hi = 0
    while top.get(lo - 1, 0.0) >= d:
        lo -= 1
    while top.get(hi + 1, 0.0) >= d:
        hi += 1
    toe_l, toe_r = xc + (lo - 0.5) * w, xc + (hi + 0.5) * w
    toe = min(toe_l - bx[0], bx[1] - toe_r)
    strays = sum(1 for r in grains if not toe_l <= float(r[ic["x"]]) <= toe_r)
    # base pressure, 4 d bins about xc, folded
    pw = 4 * d
    p = {}
    for r in floor:
        b = abs(math.floor((float(r[ic["x"]]) - xc) / pw + 0.5))
        p[b] = p.get(b, 0.0) - float(r[ic["fz"]])
    prof = {b: p[b] / ((pw if b == 0 else 2 * pw) * ly) for b in p}
    pmax = max(prof.values())
    return {
        "run": run, "engine": rj["engine"], "size": rj["size"], "point": rj["point"],
        "seed": int(v["seed"]), "source_width_d": v.get("source_width"),
        "status": rj["status"], "wall_time_s": rj["wall_time_s"], "particles": rj["particles"],
        "step": step, "n_grains": len(grains), "n_floor": len(floor), "mass": mass,
        "weight": mass * g, "base_force": base, "base_over_weight": base / (mass * g),
        "angle_left": al, "angle_right": ar,
        "angle": None if al is None or ar is None else 0.5 * (al + ar),
        "height": height, "toe_left": toe_l, "toe_right": toe_r, "toe_margin": toe, "strays": strays, "box_lx": lx, "box_ly": ly,
        "p_centre_over_max": prof.get(0, 0.0) / pmax if pmax > 0 else None,
    }


def mean_se(vals):
    vals = [x for x in vals if x is not None]
    n = len(vals)
    if n == 0:
        return None, None, 0
    m = sum(vals) / n
    if n < 2:
        return m, None, n
    sd = math.sqrt(sum((x - m) ** 2 for x in vals) / (n - 1))
    return m, sd / math.sqrt(n), n


def ensemble(root, out):
    runs = sorted(glob.glob(os.path.join(root, "seed*", "sandpile", "*-*", "*", "run.json")))
    dirs = [os.path.dirname(rj) for rj in runs if json.load(open(rj)).get("status") == "ok"]
    table(dirs, root, out)


def table(dirs, root, out):
    write_table([summarise(run) for run in dirs], root, out)


def write_table(rows, root, out):
    """OUT: the rows (their "run" made relative to root) and per engine,
    size and point the mean and SE over them (also pile_record.py summary)."""
    groups = {}
    for r in rows:
        groups.setdefault((r["engine"], r["size"], r["point"]), []).append(r)
    table = []
    for (e, s, pt), rs in sorted(groups.items()):
        row = {"engine": e, "size": s, "point": pt, "seeds": len(rs)}
        for k in ("angle", "angle_left", "angle_right", "base_over_weight", "base_force", "weight",
                  "height", "toe_margin", "strays", "p_centre_over_max", "wall_time_s"):
            m, se, n = mean_se([r[k] for r in rs])
            row[k] = m
            row[k + "_se"] = se
        table.append(row)
    for r in rows:
        r["run"] = os.path.relpath(r["run"], root)
    tmp = "%s.tmp.%d" % (out, os.getpid())
    try:
        with open(tmp, "w") as f:
            json.dump({"root": root, "groups": table, "runs": rows}, f, indent=1)
            f.write("\n")
        os.replace(tmp, out)  # atomic: no partial OUT.json
    except OSError as e:
        if os.path.exists(tmp):
            os.remove(tmp)
        fail(3, "%s: cannot write: %s" % (out, e.strerror))


def main(argv):
    if len(argv) >= 2 and argv[1] == "--runs":
        if len(argv) < 5 or argv[2] != "-o":
            fail(1, "usage: pile_summary.py --runs -o OUT.json RUN_DIR...")
        for run in argv[4:]:
            if not os.path.exists(os.path.join(run, "run.json")):
                fail(3, "%s: no run.json" % run)
        table(argv[4:], os.path.commonpath([os.path.abspath(r) for r in argv[4:]]), argv[3])
        return
    if len(argv) >= 2 and argv[1] == "--ensemble":
        if len(argv) != 5 or argv[3] != "-o":
            fail(1, "usage: pile_summary.py --ensemble ROOT -o OUT.json")
        ensemble(argv[2], argv[4])
        return
    if len(argv) < 2 or argv[1].startswith("-"):
        fail(1, "usage: pile_summary.py RUN_DIR... | --ensemble ROOT -o OUT.json")
    for run in argv[1:]:
        print(json.dumps(summarise(run)))


if __name__ == "__main__":
    main(sys.argv)
