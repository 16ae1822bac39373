#!/usr/bin/python3
"""filling2d_test.py: figures/filling2d.py on a synthetic 2D box filling
with known fields, written under WORK (the build directory). Python only:
no ekm.

    /usr/bin/python3 filling2d_test.py SOURCE_DIR WORK

The synthetic file has the layout `ekm run` writes on a 2D scenario
(docs/output-format.md "2D runs": the datasets, their `units`, the root
attributes of scenarios/thesis_filling_2d.ini; the /xdmf views are left
out, readers ignore them) on the scenario's grid, 18 x 60 cells of 0.07/18
x 0.14/60 m, frames every 0.05 s from 0 to 4 s:

  bed     phi = 0.62 in the cells whose centre lies below h(t) = 0.025 m/s
          min(t, 2.55 s) (the inflow stops at top.t_stop = 2.55 s); regime
          dense, solid from 2.9 s
  above   phi = 0.05 (the stream, kinetic) before 2.55 s; from then one
          row of phi = 0.01 on the bed and empty cells (regime 0, zeros)
  T       Tm(t) (1 + z / 0.1 m), Tm = 1e-3 exp(-max(t - 2, 0)/0.1) + 2e-5
          exp(-((t - 2.6)/0.02)^2) m^2/s^2: decaying, with a peak at 2.6 s
  v       s(t) (2 (z - 0.05), 1 (x - 0.04) - 0.5 (z - 0.05)) m/s, s =
          exp(-max(t - 2, 0)/0.2): linear, so the central differences are
          exact: shear rate 3 s(t), compression rate 0.5 s(t) 1/s
  P       P_Y(phi) + P_K(phi, T) + 1 Pa in the bed (+ 0.1 Pa above), P_Y and
          P_K the thesis's formulas (written out here, not the script's);
          sxx = -P + d, szz = -P - d, sxz = c: the deviator (d, 0, -d, c)
          (syy = -3P - sxx - szz = -P), sigma_s = sqrt(2 d^2 + 2 c^2); in
          the bed d = 0.05 P and c = 0.1 P (sigma_s/P = sqrt(0.025)) in the
          columns ix >= 6, c = 0.2 P in ix < 6 (sqrt(0.085)); above the
          bed d = 0, c = 0.5 P

Checks (filling2d.json, 7 significant digits: relative tolerance 2e-6
unless said): the monitoring cell of the default point (0.04, 0.05) m is
(ix 10, iz 21); the bed reaches it at t = 2.05 s (the first frame with
h(t) above its centre 0.050167 m); at the bed's arrival, the inflow stop
(2.55 s) and the last frame: T, the shear and compression rates, |v|,
P_Y = rho_p T0 (0.62 - 0.6)/(1 - 0.62/0.64), P - P_eq = 1 Pa (1e-6 Pa),
sigma_s/P = sqrt(0.025), the quasi-static T (the root of the local
balance, written out here); the T peak at 2.6 s, a local maximum; the
final bed: T range over the 27 x 18 bed cells, sigma_s/P mean (12
sqrt(0.025) + 6 sqrt(0.085))/18 and median sqrt(0.025), bed height 27
dz = 0.063 m; every figure file (PDF, PNG, without a date; a second run
writes the same bytes), the captions, no NaN, every null with a reason;
--point 0.07 0.14 (the far corner: cell (17, 59), empty at the end) gives
nulls with reasons. Bad inputs: a run without /sxz, a missing file and a
point outside the box give one line on stderr and statuses 2, 3, 1, and
write no filling2d.json. Exit status 77 (skipped) when /usr/bin/python3
lacks numpy, matplotlib or h5py.
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


NX, NZ, WIDTH, LENGTH = 18, 60, 0.07, 0.14
DX, DZ = WIDTH / NX, LENGTH / NZ
RHO_P, G = 1600.0, 9.81
PHI_CO, PHI_CP, T0, ETA0, ZETA0, EPS0, NU = 0.6, 0.64, 1.5, 3.55e-4, 1e-4, 500.0, 1.0
PHI_BED, PHI_STREAM, PHI_LAYER = 0.62, 0.05, 0.01
T_STOP, RISE, T_SOLID = 2.55, 0.025, 2.9
SHEAR_X, SHEAR_Z, COMP = 2.0, 1.0, 0.5        # dvx/dz, dvz/dx, -dvz/dz at s = 1 [1/s]
PV_BED, PV_DILUTE = 1.0, 0.1                  # P - P_eq [Pa]
TIMES = [0.05 * i for i in range(81)]
UNITS = {"x": "m", "z": "m", "t": "s", "phi": "1", "vx": "m/s", "vz": "m/s", "T": "m^2/s^2",
         "P": "Pa", "sxx": "Pa", "szz": "Pa", "sxz": "Pa",
         "regime": "1 (0 empty, 1 kinetic, 2 dense flow, 3 solid)"}
# the root attributes of `ekm run scenarios/thesis_filling_2d.ini` (strings, numbers)
ATTR_STR = {"bottom.type": "wall", "code_version": "0.1.0+synthetic", "created": "2026-01-01T00:00:00Z",
            "model.variant": "thesis", "scenario": "thesis_filling_2d",
            "scenario.description": "synthetic filling for filling2d_test.py",
            "scenario.name": "thesis_filling_2d", "scenario_file": "scenarios/thesis_filling_2d.ini",
            "top.type": "inflow", "variant": "thesis"}
ATTR_NUM = {"domain.cells": NZ, "domain.cells_x": NX, "domain.length": LENGTH, "domain.periodic_x": 0.0,
            "domain.width": WIDTH, "gravity.magnitude": G, "gravity_x": 0.0, "gravity_z": -G,
            "hypo.enabled": 1.0, "initial.phi": 0.0, "material.A_h": 2e8, "material.B_h": 2e8,
            "material.T0": T0, "material.alpha": 0.0, "material.eps0": EPS0, "material.eta0": ETA0,
            "material.lambda0": 3.4e-4, "material.nu": NU, "material.phi_co": PHI_CO,
            "material.phi_cp": PHI_CP, "material.rho_p": RHO_P, "material.zeta0": ZETA0,
            "numerics.phi_dry": 1e-4, "run.output_dt": 0.05, "run.t_end": 4.0,
            "stats.cell_updates": 1e6, "stats.mass_final": 1.0, "stats.mass_in": 1.0,
            "stats.newton_iterations": 1e4, "stats.rejected_steps": 0.0, "stats.steps": 1e4,
            "stats.wall_time_s": 10.0, "top.T": 1e-3, "top.phi": 0.3, "top.t_stop": T_STOP, "top.w": -0.05}


def Tm(t):
    return 1e-3 * math.exp(-max(t - 2.0, 0.0) / 0.1) + 2e-5 * math.exp(-((t - 2.6) / 0.02) ** 2)


def s_of(t):
    return math.exp(-max(t - 2.0, 0.0) / 0.2)


def h_of(t):
    return RISE * min(t, T_STOP)


def p_yield(phi):
    """The thesis's P_Y = rho_p T0 (phi - phi_co)/(1 - phi/phi_cp) above phi_co."""
    return RHO_P * T0 * (phi - PHI_CO) / (1.0 - phi / PHI_CP) if phi > PHI_CO else 0.0


def p_kinetic(phi, T):
    return RHO_P * phi * T / (1.0 - phi / PHI_CP)


def velocity(t, x, z):
    s = s_of(t)
    return s * SHEAR_X * (z - 0.05), s * (SHEAR_Z * (x - 0.04) - COMP * (z - 0.05))


def t_quasi_static(phi, shear, div):
    """The root of phi eps0 T^2 + (phi eps0 nu Y - 2/3 Ka) T - 2/3 Kb = 0
    (thesis variant: s2 = shear^2)."""
    Y = T0 * (phi - PHI_CO) / phi if phi > PHI_CO else 0.0
    ka = ETA0 * shear ** 2 + ZETA0 * div ** 2
    kb = Y * (NU * ETA0 * shear ** 2 + ZETA0 * div ** 2)
    a, b, c = phi * EPS0, phi * EPS0 * NU * Y - 2.0 / 3.0 * ka, -2.0 / 3.0 * kb
    # (-b + sqrt(b^2 - 4ac)) / (2a), as 2|c| / (b + sqrt(..)): no cancellation
    # when b > 0 (the bed: Y >> the heating), where the first loses 5 digits
    disc = math.sqrt(b * b - 4 * a * c)
    return -2 * c / (b + disc) if b > 0 else (-b + disc) / (2 * a)


def make_run(path):
    import h5py
    import numpy as np
    x = (np.arange(NX) + 0.5) * DX
    z = (np.arange(NZ) + 0.5) * DZ
    nt = len(TIMES)
    shape = (nt, NZ, NX)
    f = {n: np.zeros(shape) for n in ("phi", "vx", "vz", "T", "P", "sxx", "szz", "sxz")}
    reg = np.zeros(shape, dtype=np.int32)
    for i, t in enumerate(TIMES):
        h = h_of(t)
        for j in range(NZ):
            if z[j] < h:
                phi, r = PHI_BED, (3 if t >= T_SOLID - 1e-9 else 2)
            elif t < T_STOP - 1e-9:
                phi, r = PHI_STREAM, 1
            elif z[j] - DZ < h:            # the row on the bed
                phi, r = PHI_LAYER, 1
            else:
                continue                   # empty: zeros
            for k in range(NX):
                T = Tm(t) * (1 + z[j] / 0.1)
                vx, vz = velocity(t, x[k], z[j])
                bed = phi > 0.5
                P = p_yield(phi) + p_kinetic(phi, T) + (PV_BED if bed else PV_DILUTE)
                d = 0.05 * P if bed else 0.0
                c = (0.2 if k < 6 else 0.1) * P if bed else 0.5 * P
                for n, v in (("phi", phi), ("vx", vx), ("vz", vz), ("T", T), ("P", P),
                             ("sxx", -P + d), ("szz", -P - d), ("sxz", c)):
                    f[n][i, j, k] = v
                reg[i, j, k] = r
    with h5py.File(path, "w") as fh:
        for n, a in (("x", x), ("z", z), ("t", np.asarray(TIMES))):
            fh.create_dataset(n, data=a).attrs.create("units", np.bytes_(UNITS[n]))
        for n, a in f.items():
            fh.create_dataset(n, data=a).attrs.create("units", np.bytes_(UNITS[n]))
        fh.create_dataset("regime", data=reg).attrs.create("units", np.bytes_(UNITS["regime"]))
        for k, v in ATTR_STR.items():
            fh.attrs.create(k, np.bytes_(v))
        for k, v in ATTR_NUM.items():
            fh.attrs[k] = float(v)
        fh.attrs["ranks"] = np.int32(1)


def filling2d(src, args):
    p = subprocess.run([sys.executable, os.path.join(src, "figures", "filling2d.py")] + list(args),
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


def close(got, want, rel=2e-6, abs_=0.0):
    return got is not None and abs(got - want) <= max(rel * abs(want), abs_)


def check_frame(js, key, t, frame):
    """The monitoring cell's numbers at a key frame (the cell is in the bed)."""
    b = js["key_times"][key]
    zc, xc = (21 + 0.5) * DZ, (10 + 0.5) * DX
    s = s_of(t)
    T = Tm(t) * (1 + zc / 0.1)
    shear, comp = (SHEAR_X + SHEAR_Z) * s, COMP * s
    vx, vz = velocity(t, xc, zc)
    want = {"time": (t, 1e-9), "frame": (frame, 0), "phi": (PHI_BED, 1e-9), "T": (T, 0),
            "shear_rate": (shear, 0), "compression_rate": (comp, 0), "speed": (math.hypot(vx, vz), 0),
            "P_Y": (p_yield(PHI_BED), 0), "P_viscous": (PV_BED, 1e-6),
            "sigma_s_over_P": (math.sqrt(0.025), 0),
            "T_quasi_static": (t_quasi_static(PHI_BED, shear, -comp), 0)}
    for n, (w, a) in want.items():
        check(close(val(b, n), w, abs_=a), "%s: %s = %s, expected %.7g" % (key, n, val(b, n), w))


def synthetic(src, work):
    run = os.path.join(work, "fill.h5")
    make_run(run)
    out = os.path.join(work, "out")
    rc, so, se = filling2d(src, [run, out])
    check(rc == 0, "synthetic filling: exit status %d: %s" % (rc, se.strip()))
    for stem in ("filling2d_history", "filling2d_fields"):
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
                    check(b"thesis_filling_2d" in body and b"0.1.0+synthetic" in body,
                          "%s: no provenance (scenario, code_version) in its metadata" % p)
    check(os.path.isfile(os.path.join(out, "filling2d_captions.txt")), "no filling2d_captions.txt")
    check(not [f for f in os.listdir(out) if f.endswith(".tmp")], "temporaries left in %s" % out)
    jpath = os.path.join(out, "filling2d.json")
    if not os.path.isfile(jpath):
        check(False, "no %s" % jpath)
        return
    js, text = load_json(jpath)
    print(text)
    check("NaN" not in text and "Infinity" not in text, "filling2d.json has NaN or Infinity")
    check(not nulls_have_reasons(js, "", []), "nulls without a reason: %s" % nulls_have_reasons(js, "", []))
    check(isinstance(js.get("definitions"), dict) and "sigma_s" in js["definitions"]
          and "rates" in js["definitions"], "no definitions of sigma_s and the rates")
    prov = js["input"]
    check(prov["scenario"] == "thesis_filling_2d" and prov["code_version"] == "0.1.0+synthetic"
          and prov["created"] == "2026-01-01T00:00:00Z" and prov["file"] == os.path.abspath(run),
          "provenance: %s" % prov)

    mc = js["monitoring_cell"]
    check(val(mc, "ix") == 10 and val(mc, "iz") == 21, "monitoring cell (%s, %s), expected (10, 21)"
          % (val(mc, "ix"), val(mc, "iz")))
    cen = val(mc, "centre")
    check(close(cen[0], 10.5 * DX) and close(cen[1], 21.5 * DZ), "monitoring cell centre %s" % cen)

    # the bed reaches the cell's centre 21.5 dz = 0.0501667 m at 2.0067 s: the frame t = 2.05 s
    check(close(val(js, "key_times", "bed_arrival", "time"), 2.05, abs_=1e-9),
          "bed arrival at %s s, expected 2.05" % val(js, "key_times", "bed_arrival", "time"))
    check_frame(js, "bed_arrival", 2.05, 41)
    # 0.025 x 2.05 = 0.05125 m: 22 rows below it
    check(close(val(js, "key_times", "bed_arrival", "bed_height"), 22 * DZ),
          "bed height at the arrival %s, expected %.7g" % (val(js, "key_times", "bed_arrival", "bed_height"),
                                                           22 * DZ))
    check_frame(js, "inflow_stop", 2.55, 51)
    check(close(val(js, "key_times", "inflow_stop", "t_stop"), 2.55), "t_stop")
    check_frame(js, "last_frame", 4.0, 80)
    check(js["key_times"]["last_frame"]["regime"] == "solid", "last frame regime %r"
          % js["key_times"]["last_frame"]["regime"])
    check(close(val(js, "key_times", "bed_arrival", "P_Y"), 1536.0, rel=1e-6),
          "P_Y at phi 0.62: %s, expected 1600 x 1.5 x 0.02 x 32 = 1536 Pa"
          % val(js, "key_times", "bed_arrival", "P_Y"))

    pk = js["T_peak"]
    zc = 21.5 * DZ
    check(close(val(pk, "time"), 2.6, abs_=1e-9) and close(val(pk), Tm(2.6) * (1 + zc / 0.1))
          and pk["local_maximum"] is True,
          "T peak %s at %s s (local maximum %r), expected %.7g at 2.6 s, true"
          % (val(pk), val(pk, "time"), pk.get("local_maximum"), Tm(2.6) * (1 + zc / 0.1)))

    fin = js["final"]
    check(val(fin, "bed_cells") == 27 * NX,
          "final bed cells %s, expected %d" % (val(fin, "bed_cells"), 27 * NX))
    check(close(val(fin, "bed_height"), 27 * DZ) and close(27 * DZ, 0.063, rel=1e-12),
          "final bed height %s m, expected 27 dz = 0.063" % val(fin, "bed_height"))
    tr = val(fin, "T_range")
    want = [Tm(4.0) * (1 + 0.5 * DZ / 0.1), Tm(4.0) * (1 + 26.5 * DZ / 0.1)]
    check(tr is not None and close(tr[0], want[0]) and close(tr[1], want[1]),
          "final T range %s, expected %s" % (tr, want))
    r1, r2 = math.sqrt(0.025), math.sqrt(0.085)
    mean = (12 * r1 + 6 * r2) / 18
    check(close(val(fin, "sigma_s_over_P_mean"), mean),
          "final sigma_s/P mean %s, expected %.7g" % (val(fin, "sigma_s_over_P_mean"), mean))
    check(close(val(fin, "sigma_s_over_P_median"), r1),
          "final sigma_s/P median %s, expected %.7g" % (val(fin, "sigma_s_over_P_median"), r1))

    # deterministic: a second run writes the same bytes
    old = {f: open(os.path.join(out, f), "rb").read() for f in ("filling2d.json", "filling2d_history.pdf",
                                                                  "filling2d_fields.pdf")}
    rc, _, se = filling2d(src, [run, out])
    check(rc == 0, "second run: exit status %d: %s" % (rc, se.strip()))
    for f, body in old.items():
        check(open(os.path.join(out, f), "rb").read() == body, "second run: %s differs" % f)

    # the far corner: the top row is empty at the end, the bed never reaches it
    out2 = os.path.join(work, "out-corner")
    rc, _, se = filling2d(src, [run, out2, "--point", "0.07", "0.14"])
    check(rc == 0, "--point 0.07 0.14: exit status %d: %s" % (rc, se.strip()))
    if rc == 0:
        js, text = load_json(os.path.join(out2, "filling2d.json"))
        mc = js["monitoring_cell"]
        last = js["key_times"]["last_frame"]
        check(val(mc, "ix") == NX - 1 and val(mc, "iz") == NZ - 1, "--point 0.07 0.14: cell (%s, %s)"
              % (val(mc, "ix"), val(mc, "iz")))
        check(val(js, "key_times", "bed_arrival", "time") is None and val(last, "T") is None
              and "empty" in last["T"]["reason"] and last["regime"] == "empty",
              "--point 0.07 0.14: expected nulls (never bed, empty at the end): %s"
              % json.dumps(js["key_times"])[:400])
        check(not nulls_have_reasons(js, "", []), "--point 0.07 0.14: nulls without a reason")
        check("NaN" not in text, "--point 0.07 0.14: NaN in the JSON")


def bad_inputs(src, work):
    import h5py
    cases = []
    no_sxz = os.path.join(work, "no_sxz.h5")
    shutil.copy(os.path.join(work, "fill.h5"), no_sxz)
    with h5py.File(no_sxz, "a") as fh:
        del fh["sxz"]
    cases.append(("a run without /sxz", [no_sxz], 2, ["no_sxz.h5", "/sxz", "missing"]))
    cases.append(("a missing file", [os.path.join(work, "no-such.h5")], 3, ["no-such.h5", "missing"]))
    cases.append(("a point outside the box", [os.path.join(work, "fill.h5"), "--point", "0.1", "0.05"], 1,
                  ["--point", "outside"]))
    for i, (what, args, status, needles) in enumerate(cases):
        out = os.path.join(work, "bad-%d" % i)
        shutil.rmtree(out, ignore_errors=True)
        rc, so, se = filling2d(src, [args[0], out] + args[1:])
        lines = se.strip().splitlines()
        check(rc == status, "%s: exit status %d, expected %d (%s)" % (what, rc, status, se.strip()))
        check(len(lines) == 1, "%s: expected one line on stderr, got %r" % (what, se))
        for n in needles:
            check(n in se, "%s: stderr does not name %r: %s" % (what, n, se.strip()))
        check(not os.path.exists(os.path.join(out, "filling2d.json")), "%s: filling2d.json written" % what)
        print("%s: %d: %s" % (what, rc, lines[-1] if lines else ""))


def main():
    if len(sys.argv) != 3:
        print("usage: filling2d_test.py SOURCE_DIR WORK", file=sys.stderr)
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
    if failures:
        print("%d failure(s)" % len(failures), file=sys.stderr)
        return 1
    print("ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
