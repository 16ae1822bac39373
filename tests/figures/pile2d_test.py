#!/usr/bin/python3
"""pile2d_test.py: figures/pile2d.py on a synthetic 2D run with a known
pile, written under WORK (the build directory). Python only: no ekm.

    /usr/bin/python3 pile2d_test.py SOURCE_DIR WORK

The synthetic file has the layout `ekm run` writes on a 2D scenario
(docs/output-format.md "2D runs": the datasets, their `units`, the root
attributes, copied from a run of scenarios/thesis_sandpile_2d.ini on
14 x 7 cells; the /xdmf views are left out, readers ignore them) on the
scenario's grid, 56 x 28 cells of 2.5 mm, with four frames:

  t = 0    empty
  t = 0.5  the jet only (phi 0.05 under the inlet): no pile
  t = 3.5  a triangular pile, 30 degrees on both sides, 0.03 m high, apex
           at x = 0.07 m (between the two middle columns); each cell's phi
           is 0.605 - 0.01 exp(-((x - 0.07)/8 mm)^2) (looser under the
           apex, as thesis Fig. 4.19) times the fraction of the cell under
           the surface; the base pressure (bottom row) P(max) (1 - ((|x -
           0.07| - r)/(R - r))^2) outside r = 4.5 dx (R the toe) and
           P(max) (1 - 0.15 (1 - ((x - 0.07)/r)^2)) inside: a dip with
           maxima at the cell centres x = 0.07 -+ r = 0.05875, 0.08125 m
           and P(centre)/P(max) = 1 - 0.15 (1 - (0.5/4.5)^2) = 0.85185 at
           the two middle columns; plus 0.001 P(max) u, u uniform in
           [-1, 1] (seeded): cell-to-cell noise of standard deviation
           0.001/sqrt(3) P(max)
  t = 5    a pile of 28 degrees on the left and 24 on the right, 0.025 m
           high, apex at the centre of column 28 (x = 0.07125 m), the base
           pressure a parabola with its maximum there: no dip, ratio 1,
           both maxima at x = 0.07125 m

Checks: the slopes within the resolution pile2d.json states for them (the
angle a height error of one cell, dz = 2.5 mm, across the fitted extent
makes: about 3.5 degrees on this grid; the test also requires it below 4;
the fits are within 0.1 degree here),
the height within half a cell of the surface over the apex columns, the
apex x, the ratio P(centre)/P(max) (within 0.003, the noise), the maxima
positions (exact: cell centres), the dip (and none at t = 5), phi under
the apex below the flanks', the noise estimate within a factor 2 of the
noise put in; the PDF and PNG files (PDF without a date: a second run
writes the same bytes, the JSON too); every null has a reason and there is
no NaN; --base-time 0.5 (no pile) gives nulls; a 1D ekm output (layout of
docs/output-format.md "Datasets"), a file without /P, a missing file and a
bad --times give one line on stderr and statuses 2, 2, 3, 1, and write no
pile2d.json. Exit status 77 (skipped) when /usr/bin/python3 lacks numpy,
matplotlib or h5py.
"""
import json
import math
import os
import shutil
import subprocess
import sys

failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL: " + msg, file=sys.stderr)


NX, NZ, WIDTH, LENGTH = 56, 28, 0.14, 0.07
DX, DZ = WIDTH / NX, LENGTH / NZ
RHO_P, G = 1600.0, 9.81
TIMES = [0.0, 0.5, 3.5, 5.0]
UNITS = {"x": "m", "z": "m", "t": "s", "phi": "1", "vx": "m/s", "vz": "m/s", "T": "m^2/s^2",
         "P": "Pa", "sxx": "Pa", "szz": "Pa", "sxz": "Pa",
         "regime": "1 (0 empty, 1 kinetic, 2 dense flow, 3 solid)"}
# the root attributes of `ekm run scenarios/thesis_sandpile_2d.ini` (strings, numbers)
ATTR_STR = {"bottom.type": "wall", "code_version": "0.1.0+synthetic", "created": "2026-01-01T00:00:00Z",
            "model.variant": "thesis", "scenario": "thesis_sandpile_2d",
            "scenario.description": "synthetic pile for pile2d_test.py",
            "scenario.name": "thesis_sandpile_2d", "scenario_file": "scenarios/thesis_sandpile_2d.ini",
            "top.type": "inflow", "variant": "thesis"}
ATTR_NUM = {"domain.cells": NZ, "domain.cells_x": NX, "domain.length": LENGTH, "domain.periodic_x": 0.0,
            "domain.width": WIDTH, "gravity.magnitude": G, "gravity_x": 0.0, "gravity_z": -G,
            "initial.phi": 0.0, "material.A_h": 2e8, "material.B_h": 2e8, "material.T0": 1.5,
            "material.alpha": 0.0, "material.eps0": 500.0, "material.eta0": 3.55e-4,
            "material.lambda0": 3.4e-4, "material.nu": 1.0, "material.phi_co": 0.6,
            "material.phi_cp": 0.64, "material.rho_p": RHO_P, "material.zeta0": 1e-4,
            "numerics.phi_dry": 1e-4, "run.output_dt": 0.05, "run.t_end": 5.0,
            "stats.cell_updates": 1e6, "stats.mass_final": 1.0, "stats.mass_in": 1.0,
            "stats.newton_iterations": 1e4, "stats.rejected_steps": 0.0, "stats.steps": 1e4,
            "stats.wall_time_s": 10.0, "top.T": 1e-3, "top.inlet_width": 0.01, "top.inlet_x": 0.07,
            "top.phi": 0.3, "top.t_stop": 2.55, "top.w": -0.05}

# the base-time pile (t = 3.5) and the last one (t = 5)
BASE = dict(xa=0.07, H=0.03, left=30.0, right=30.0)
LAST = dict(xa=0.07125, H=0.025, left=28.0, right=24.0)
R_MAX = 4.5 * DX            # maxima of the base-time pressure at xa -+ R_MAX
DIP = 0.15
NOISE = 1e-3                # of P(max), uniform in [-NOISE, NOISE]
RATIO = 1 - DIP * (1 - (0.5 * DX / R_MAX) ** 2)


def surface(x, p):
    """The pile's surface height [m] at x (triangle, clipped at 0)."""
    import numpy as np
    tl, tr = math.tan(math.radians(p["left"])), math.tan(math.radians(p["right"]))
    s = np.where(x < p["xa"], p["H"] - tl * (p["xa"] - x), p["H"] - tr * (x - p["xa"]))
    return np.clip(s, 0.0, None)


def pile_phi(p, bulk):
    """phi [nz][nx]: bulk(x) times the fraction of each cell under the surface
    (the mean over 200 sub-columns of the clipped height in the cell)."""
    import numpy as np
    phi = np.zeros((NZ, NX))
    sub = (np.arange(200) + 0.5) / 200
    for k in range(NX):
        xs = (k + sub) * DX
        s = surface(xs, p)
        for j in range(NZ):
            frac = np.clip((s - j * DZ) / DZ, 0.0, 1.0).mean()
            phi[j, k] = bulk((k + 0.5) * DX) * frac
    return phi


def make_run(path):
    import h5py
    import numpy as np
    x = (np.arange(NX) + 0.5) * DX
    z = (np.arange(NZ) + 0.5) * DZ
    nt = len(TIMES)
    phi = np.zeros((nt, NZ, NX))
    P = np.zeros((nt, NZ, NX))
    # t = 0.5: the jet under the 10 mm inlet
    phi[1][:, np.abs(x - 0.07) < 0.005] = 0.05
    # t = 3.5: the base-time pile, looser under the apex, the dip
    phi[2] = pile_phi(BASE, lambda xx: 0.605 - 0.01 * math.exp(-((xx - 0.07) / 0.008) ** 2))
    Pm = RHO_P * 0.6 * G * BASE["H"]
    toe = BASE["H"] / math.tan(math.radians(BASE["left"]))
    d = np.abs(x - BASE["xa"])
    f = np.where(d >= R_MAX, 1 - ((d - R_MAX) / (toe - R_MAX)) ** 2, 1 - DIP * (1 - (d / R_MAX) ** 2))
    rng = np.random.default_rng(33)
    base = Pm * (np.clip(f, 0.0, None) + NOISE * rng.uniform(-1, 1, NX))
    base[phi[2][0] <= 0.3] = 0.0
    s = surface(x, BASE)
    with np.errstate(divide="ignore", invalid="ignore"):
        P[2] = np.where(s > 0, base * np.clip(1 - z[:, None] / s, 0, None), 0.0)
    P[2][0] = base
    # t = 5: another pile, no dip
    phi[3] = pile_phi(LAST, lambda xx: 0.6)
    toe = LAST["H"] / math.tan(math.radians(LAST["right"]))
    base = RHO_P * 0.6 * G * LAST["H"] * np.clip(1 - ((x - LAST["xa"]) / toe) ** 2, 0.0, None)
    base[phi[3][0] <= 0.3] = 0.0
    P[3][0] = base
    with h5py.File(path, "w") as fh:
        for n, a in (("x", x), ("z", z), ("t", np.asarray(TIMES))):
            fh.create_dataset(n, data=a).attrs.create("units", np.bytes_(UNITS[n]))
        fields = {"phi": phi, "P": P, "vx": np.zeros_like(phi), "vz": -0.5 * (phi > 0) * (phi < 0.3),
                  "T": 1e-3 * (phi > 0) * (phi < 0.3), "sxx": -P, "szz": -P, "sxz": np.zeros_like(P)}
        for n, a in fields.items():
            fh.create_dataset(n, data=a).attrs.create("units", np.bytes_(UNITS[n]))
        reg = np.where(phi > 0.6, 2, np.where(phi > 1e-4, 1, 0)).astype(np.int32)
        fh.create_dataset("regime", data=reg).attrs.create("units", np.bytes_(UNITS["regime"]))
        for k, v in ATTR_STR.items():
            fh.attrs.create(k, np.bytes_(v))
        for k, v in ATTR_NUM.items():
            fh.attrs[k] = float(v)
        fh.attrs["ranks"] = np.int32(1)


def make_1d(path):
    """A 1D ekm output (docs/output-format.md "Datasets"): /z, /t, [nt][nz] fields."""
    import h5py
    import numpy as np
    z = (np.arange(20) + 0.5) * 0.005
    with h5py.File(path, "w") as fh:
        fh.create_dataset("z", data=z).attrs.create("units", np.bytes_("m"))
        fh.create_dataset("t", data=np.array([0.0, 1.0])).attrs.create("units", np.bytes_("s"))
        for n in ("phi", "vx", "vz", "T", "P", "sxz", "szz"):
            fh.create_dataset(n, data=np.zeros((2, 20))).attrs.create("units", np.bytes_(UNITS[n]))
        fh.create_dataset("regime", data=np.zeros((2, 20), np.int32)).attrs.create(
            "units", np.bytes_(UNITS["regime"]))
        for k, v in ATTR_STR.items():
            fh.attrs.create(k, np.bytes_(v))
        fh.attrs["material.rho_p"] = RHO_P
        fh.attrs["material.phi_co"] = 0.6


def pile2d(src, args):
    p = subprocess.run([sys.executable, os.path.join(src, "figures", "pile2d.py")] + list(args),
                       capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def load_json(path):
    def no_const(c):
        raise ValueError("%s in the JSON" % c)
    with open(path) as fh:
        text = fh.read()
    return json.loads(text, parse_constant=no_const), text


def nulls_have_reasons(node, where, bad):
    if isinstance(node, dict):
        if "value" in node and node["value"] is None and not node.get("reason"):
            bad.append(where)
        for k, v in node.items():
            nulls_have_reasons(v, where + "." + k, bad)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            nulls_have_reasons(v, "%s[%d]" % (where, i), bad)
    return bad


def val(js, *keys):
    for k in keys:
        js = js[k]
    return js["value"] if isinstance(js, dict) and "value" in js else js


def synthetic(src, work):
    import numpy as np
    run = os.path.join(work, "pile.h5")
    make_run(run)
    out = os.path.join(work, "out")
    rc, so, se = pile2d(src, [run, out])
    check(rc == 0, "synthetic pile: exit status %d: %s" % (rc, se.strip()))
    for stem in ("pile2d_phi", "pile2d_pressure"):
        for ext, magic in (("pdf", b"%PDF"), ("png", b"\x89PNG\r\n\x1a\n")):
            p = os.path.join(out, "%s.%s" % (stem, ext))
            ok = os.path.isfile(p) and os.path.getsize(p) > 1000
            check(ok, "%s missing or empty" % p)
            if ok:
                with open(p, "rb") as fh:
                    body = fh.read()
                check(body.startswith(magic), "%s is not a %s" % (p, ext.upper()))
                if ext == "pdf":
                    check(b"CreationDate" not in body, "%s has a CreationDate" % p)
                    check(b"thesis_sandpile_2d" in body and b"0.1.0+synthetic" in body,
                          "%s: no provenance (scenario, code_version) in its metadata" % p)
    check(os.path.isfile(os.path.join(out, "pile2d_captions.txt")), "no pile2d_captions.txt")
    check(not [f for f in os.listdir(out) if f.endswith(".tmp")], "temporaries left in %s" % out)
    jpath = os.path.join(out, "pile2d.json")
    if not os.path.isfile(jpath):
        check(False, "no %s" % jpath)
        return
    js, text = load_json(jpath)
    print(text)
    check("NaN" not in text and "Infinity" not in text, "pile2d.json has NaN or Infinity")
    check(not nulls_have_reasons(js, "", []), "nulls without a reason: %s" % nulls_have_reasons(js, "", []))
    prov = js["input"]
    check(prov["scenario"] == "thesis_sandpile_2d" and prov["code_version"] == "0.1.0+synthetic"
          and prov["created"] == "2026-01-01T00:00:00Z" and prov["file"] == os.path.abspath(run),
          "provenance: %s" % prov)

    b = js["base_time"]
    check(val(b, "time") == 3.5 and val(b, "asked") == 3.5, "base time %s" % val(b, "time"))
    check(b["bed"] == "pile", "base time: bed %r, expected 'pile'" % b["bed"])
    for side in ("left", "right"):
        sl = b["slope_" + side]
        ang, res = val(sl, "angle"), val(sl, "resolution")
        check(ang is not None and res is not None and res < 4.0 and abs(ang - BASE[side]) <= res,
              "base time: %s slope %s deg, expected %g within the resolution %s deg (< 4)"
              % (side, ang, BASE[side], res))
    # the apex columns' surface (the mean over the cell of the triangle)
    xs = 0.07 - DX + (np.arange(400) + 0.5) / 400 * 2 * DX
    h_apex = float(surface(xs, BASE).mean())
    check(abs(val(b, "height") - h_apex) < 0.5 * DZ, "base time: height %s m, expected %.5f +- dz/2"
          % (val(b, "height"), h_apex))
    check(abs(val(b, "apex_x") - 0.07) < 1e-9, "base time: apex_x %s, expected 0.07" % val(b, "apex_x"))
    bp = b["base_pressure"]
    check(abs(val(bp, "ratio_centre_to_max") - RATIO) < 0.003,
          "base time: P(centre)/P(max) %s, expected %.5f +- 0.003 (noise)" % (val(bp, "ratio_centre_to_max"), RATIO))
    check(abs(val(bp, "x_max_left") - (0.07 - R_MAX)) < 1e-9 and abs(val(bp, "x_max_right") - (0.07 + R_MAX)) < 1e-9,
          "base time: maxima at %s, %s m, expected %.5f, %.5f" % (val(bp, "x_max_left"), val(bp, "x_max_right"),
                                                                   0.07 - R_MAX, 0.07 + R_MAX))
    dip = b["dip"]
    check(dip["value"] is True, "base time: dip %r, expected true" % dip["value"])
    sigma = NOISE / math.sqrt(3) * RHO_P * 0.6 * G * BASE["H"]
    check(0.5 * sigma < val(dip, "noise") < 2 * sigma, "base time: noise %s Pa, put in %.4g Pa (factor 2)"
          % (val(dip, "noise"), sigma))
    # the base profile's extrema (several sources' numbers): the two maxima and the dip between
    ex = b["base_extrema"]
    xs_max = [val(m, "x") for m in ex["maxima"]]
    xs_min = [val(m, "x") for m in ex["minima"]]
    check(len(xs_max) == 2 and abs(xs_max[0] - (0.07 - R_MAX)) < 1e-9 and abs(xs_max[1] - (0.07 + R_MAX)) < 1e-9
          and len(xs_min) == 1 and abs(xs_min[0] - 0.07) < DX,
          "base time: base_extrema maxima at %s, minima at %s m: expected %.5f, %.5f and 0.07 +- dx/2"
          % (xs_max, xs_min, 0.07 - R_MAX, 0.07 + R_MAX))
    if len(xs_min) == 1:
        r = val(ex["minima"][0], "ratio_to_highest_max")
        check(abs(r - RATIO) < 0.005, "base time: base_extrema minimum/maximum %s, expected %.5f +- 0.005"
              % (r, RATIO))
    pa, pf = val(b, "phi_apex"), val(b, "phi_flank")
    check(pa is not None and pf is not None and pa < pf - 0.007 and abs(pa - 0.5952) < 0.001,
          "base time: phi under the apex %s, on the flanks %s: expected about 0.5952 and > 0.602" % (pa, pf))

    last = js["last_frame"]
    check(val(last, "time") == 5.0 and last["bed"] == "pile", "last frame: t %s, bed %r"
          % (val(last, "time"), last["bed"]))
    for side in ("left", "right"):
        sl = last["slope_" + side]
        ang, res = val(sl, "angle"), val(sl, "resolution")
        check(ang is not None and res is not None and res < 4.0 and abs(ang - LAST[side]) <= res,
              "last frame: %s slope %s deg, expected %g within the resolution %s deg" % (side, ang, LAST[side], res))
    bp = last["base_pressure"]
    check(val(bp, "ratio_centre_to_max") == 1.0 and last["dip"]["value"] is False,
          "last frame: ratio %s, dip %r: expected 1 and false" % (val(bp, "ratio_centre_to_max"), last["dip"]["value"]))
    check(abs(val(bp, "x_max_left") - 0.07125) < 1e-9 and abs(val(bp, "x_max_right") - 0.07125) < 1e-9,
          "last frame: maxima at %s, %s m, expected both at the apex 0.07125" % (val(bp, "x_max_left"),
                                                                              val(bp, "x_max_right")))

    # --extrema (several sources): draws, and says so in the caption
    out_x = os.path.join(work, "out-extrema")
    rc, _, se = pile2d(src, [run, out_x, "--extrema"])
    check(rc == 0, "--extrema: exit status %d: %s" % (rc, se.strip()))
    if rc == 0:
        cap = open(os.path.join(out_x, "pile2d_captions.txt")).read()
        check("local maxima and minima" in cap and "inlets' centres" in cap, "--extrema: caption %r" % cap[-400:])

    # deterministic: a second run writes the same bytes
    old = {f: open(os.path.join(out, f), "rb").read() for f in ("pile2d.json", "pile2d_phi.pdf",
                                                                  "pile2d_pressure.pdf")}
    rc, _, se = pile2d(src, [run, out])
    check(rc == 0, "second run: exit status %d: %s" % (rc, se.strip()))
    for f, body in old.items():
        check(open(os.path.join(out, f), "rb").read() == body, "second run: %s differs" % f)

    # no pile at the base time: nulls with reasons, no NaN
    out2 = os.path.join(work, "out-early")
    rc, _, se = pile2d(src, [run, out2, "--base-time", "0.5", "--times", "0.5"])
    check(rc == 0, "--base-time 0.5: exit status %d: %s" % (rc, se.strip()))
    if rc == 0:
        js, text = load_json(os.path.join(out2, "pile2d.json"))
        b = js["base_time"]
        check(b["bed"] == "none" and val(b, "height") is None and "no pile" in b["height"]["reason"]
              and b["dip"]["value"] is None and val(b, "slope_left", "angle") is None
              and val(b, "base_pressure", "ratio_centre_to_max") is None,
              "--base-time 0.5 (the jet only): expected nulls, got %s" % json.dumps(b)[:400])
        check(not nulls_have_reasons(js, "", []), "--base-time 0.5: nulls without a reason")
        check(js["last_frame"]["bed"] == "pile", "--base-time 0.5: the last frame is not a pile")


def bad_inputs(src, work):
    import h5py
    cases = []
    one_d = os.path.join(work, "one_d.h5")
    make_1d(one_d)
    cases.append(("a 1D run", [one_d], 2, ["one_d.h5", "/x", "1D"]))
    no_p = os.path.join(work, "no_p.h5")
    shutil.copy(os.path.join(work, "pile.h5"), no_p)
    with h5py.File(no_p, "a") as fh:
        del fh["P"]
    cases.append(("a run without /P", [no_p], 2, ["no_p.h5", "/P", "missing"]))
    cases.append(("a missing file", [os.path.join(work, "no-such.h5")], 3, ["no-such.h5", "missing"]))
    cases.append(("bad --times", [os.path.join(work, "pile.h5"), "--times", "1,x"], 1, ["--times"]))
    for i, (what, args, status, needles) in enumerate(cases):
        out = os.path.join(work, "bad-%d" % i)
        shutil.rmtree(out, ignore_errors=True)
        rc, so, se = pile2d(src, [args[0], out] + args[1:])
        lines = se.strip().splitlines()
        if status == 1:          # argparse: the usage line, then the message
            lines = lines[-1:]
        check(rc == status, "%s: exit status %d, expected %d (%s)" % (what, rc, status, se.strip()))
        check(len(lines) == 1, "%s: expected one line on stderr, got %r" % (what, se))
        for n in needles:
            check(n in se, "%s: stderr does not name %r: %s" % (what, n, se.strip()))
        check(not os.path.exists(os.path.join(out, "pile2d.json")), "%s: pile2d.json written" % what)
        print("%s: %d: %s" % (what, rc, lines[-1] if lines else ""))


def table(src, work):
    """figures/pile2d_table.py over the synthetic folders: a row per folder
    with pile2d.json's numbers, the DEM rows of a summary, one error line for
    a broken pile2d.json and no output then."""
    import json
    tab = os.path.join(work, "table.md")
    dem = os.path.join(work, "dem-summary.json")
    with open(dem, "w") as fh:
        json.dump({"groups": [{"engine": "lammps", "point": "source8", "seeds": 3, "height": 0.0407,
                               "height_se": 0.0002, "angle_left": 22.0, "angle_left_se": 0.7,
                               "angle_right": 22.4, "angle_right_se": 0.3, "p_centre_over_max": 0.81,
                               "p_centre_over_max_se": 0.027}]}, fh)
    # an ekmcompare score2d output in the folder: a row of the scores' table
    with open(os.path.join(work, "out", "score2d-lammps-plain.json"), "w") as fh:
        json.dump({"tool": "ekmcompare score2d",
                   "dem": {"path": "maps.h5", "group": "/lammps/plain/hopper", "t_s": None},
                   "model": {"path": "run.h5", "group": None, "t_s": 4.2},
                   "fields": {"phi": {"units": "1", "points": 85, "rel_l2": 0.0512,
                                      "interior": {"points": 37, "rel_l2": 0.0431}},
                              "szz": {"units": "Pa", "points": 85, "rel_l2": 0.25,
                                      "interior": {"points": 37, "rel_l2": None}}}}, fh)
    cmd = [sys.executable, os.path.join(src, "figures", "pile2d_table.py"), work, tab, "--title", "T",
           "--about", "A", "--dem", dem]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
    check(p.returncode == 0, "pile2d_table: exit %d: %s" % (p.returncode, p.stderr.strip()))
    rows = open(tab).read().splitlines() if os.path.isfile(tab) else []
    js, _ = load_json(os.path.join(work, "out", "pile2d.json"))
    b = js["base_time"]
    want = "| out | %g | %s | %.1f |" % (b["time"]["value"], b["bed"], b["height"]["value"] * 1e3)
    check(any(r.startswith(want) for r in rows), "pile2d_table: no row starting %r in %s" % (want, tab))
    check("| DEM lammps source8 (3 seeds) | at rest | pile | 40.7 +- 0.2 | 22.0 +- 0.7, 22.4 +- 0.3 | - "
          "| 0.810 +- 0.027 | - | - |" in rows, "pile2d_table: the DEM row is not as given")
    check(rows[:1] == ["# T"], "pile2d_table: title %r" % rows[:1])
    want = "| out | t = 4.2 s | /lammps/plain/hopper | 85 / 37 | 0.051 / 0.043 | - | 0.250 / - | - |"
    check(want in rows, "pile2d_table: no scores row %r in %s" % (want, tab))
    bad = os.path.join(work, "tab-bad")
    os.makedirs(os.path.join(bad, "broken"), exist_ok=True)
    with open(os.path.join(bad, "broken", "pile2d.json"), "w") as fh:
        fh.write("{\"base_time\": {}}")
    out = os.path.join(bad, "t.md")
    p = subprocess.run(cmd[:2] + [bad, out, "--title", "T", "--about", "A"], capture_output=True, text=True,
                       timeout=60)
    lines = p.stderr.strip().splitlines()
    check(p.returncode == 2 and len(lines) == 1 and "broken/pile2d.json" in lines[0],
          "pile2d_table on a broken pile2d.json: exit %d, stderr %r" % (p.returncode, p.stderr))
    check(not os.path.exists(out) and not os.path.exists(out + ".tmp"), "pile2d_table: output left on error")
    n = sum(r.startswith("| ") for r in rows) - 1  # less the header
    print("pile2d_table: %d rows; broken pile2d.json: %s" % (n, lines[-1] if lines else ""))


def main():
    if len(sys.argv) != 3:
        print("usage: pile2d_test.py SOURCE_DIR WORK", file=sys.stderr)
        return 2
    src, work = sys.argv[1], sys.argv[2]
    try:
        import numpy  # noqa: F401
        import h5py  # noqa: F401
        import matplotlib  # noqa: F401
    except ImportError as e:
        print("skipped: %s (scripts/deps.sh figures)" % e)
        return 77
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    synthetic(src, work)
    bad_inputs(src, work)
    table(src, work)
    if failures:
        print("%d failure(s)" % len(failures), file=sys.stderr)
        return 1
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
