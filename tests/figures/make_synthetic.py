#!/usr/bin/python3
"""make_synthetic.py: a small synthetic campaign results folder for the
tests of figures/make_figures.py, with the shapes, datasets and attributes
of the real ones (compare/cg_run.c, continuum/h5out.c, scripts/campaign/).

    /usr/bin/python3 make_synthetic.py --layout ref|smoke OUT

ref:   chute at theta22, theta24 (both engines), filling and shear_cell
       single cases, simple_shear at phi0.50-rate5, phi0.50-rate10,
       phi0.53-rate5, phi0.53-rate10 (LAMMPS only), simple_shear_p at
       p10-rate10, p100-rate10 (LAMMPS only)
       and the calibration: calibration.json (the fixture
       tests/figures/calibration.json), calibration/rheology/fit.ini (a
       fitted [material]) with its runs ekm_rheology.h5 in the chute points
       and shear_cell, and calibration/chute/ without fit.ini (a set that
       did not fit: left out by the figures)
smoke: every scenario a single case (simple_shear's phi and rate then come
       from the EKM attributes); no calibration
Profiles are smooth made-up shapes (a Bagnold-like chute, a filling front,
a linear shear profile), not physics: only what the figures read matters.
"""
import argparse
import json
import os

import h5py
import numpy as np

D = 0.002          # m, grain diameter
RHO_P = 2500.0
MATERIAL = {"rho_p": RHO_P, "phi_co": 0.6, "phi_cp": 0.64, "T0": 1.5, "eta0": 3.55e-4,
            "zeta0": 1e-4, "lambda0": 3.4e-4, "eps0": 212.2, "nu": 1.0, "A_h": 2e8, "B_h": 2e8,
            "alpha": 0.0}
CG_FIELDS = ("phi", "rho", "vx", "vy", "vz", "T", "P", "sxz", "szz", "mu", "I")
EKM_FIELDS = ("phi", "vx", "vz", "T", "P", "sxz", "szz")
# field -> units, from the field schema (common/schema.c) as the build
# writes it, build/generated/fields.json (--fields): filled by main()
UNITS = {}


def load_units(path):
    """field -> units of the generated schema file."""
    with open(path) as fh:
        return {k: v["units"] for k, v in json.load(fh)["fields"].items()}
FIELDS = {"chute": "phi,vx,T,P,sxz,szz", "filling": "phi,vz,T,P,szz",
          "shear_cell": "phi,vx,T,P,sxz,szz", "simple_shear": "phi,T,P,sxz,szz",
          "simple_shear_p": "phi,T,P,sxz,szz"}
# [compare] ekm_time of the scenario files (what the scores record)
EKM_TIME = {"chute": "last", "filling": "interp", "shear_cell": "last", "simple_shear": "last",
            "simple_shear_p": "last"}


def _str(f, k, v):
    f.attrs.create(k, np.bytes_(v))


def write_cg(path, z, t, prof, rng, engine, extra=None):
    """prof(z, t) -> dict of [nz] arrays per field; SE 3% plus noise."""
    with h5py.File(path, "w") as f:
        f.create_dataset("z", data=z).attrs.create("units", np.bytes_(UNITS["z"]))
        f.create_dataset("t", data=np.asarray(t, float)).attrs.create("units", np.bytes_(UNITS["t"]))
        f.create_dataset("nsnapshots", data=np.full(len(t), 8.0)).attrs.create("units", np.bytes_(UNITS["nsnapshots"]))
        rows = [prof(z, tt) for tt in t]
        for n in CG_FIELDS:
            v = np.array([r[n] for r in rows]) * (1 + 0.01 * rng.standard_normal((len(t), z.size)))
            se = 0.03 * np.abs(v) + 1e-6
            if n in ("vx", "vy", "vz", "T"):
                empty = np.array([r["phi"] for r in rows]) <= 0
                v[empty], se[empty] = np.nan, np.nan
            f.create_dataset(n, data=v).attrs.create("units", np.bytes_(UNITS[n]))
            f.create_dataset(n + "_se", data=se).attrs.create("units", np.bytes_(UNITS[n]))
        for k, v in {"axis": "z", "kernel": "gauss", "boundary": "walls: kernel reflected",
                     "atom_types": "1", "temperature": "particle",
                     "inputs": "runs/synthetic/%s/atoms.dump" % engine,
                     "code_version": "0.1.0+synthetic"}.items():
            _str(f, k, v)
        for k, v in {"mean_diameter": D * (1.0 if engine == "lammps" else 0.998), "width": D,
                     "dz": z[1] - z[0], "lo": z[0] - (z[1] - z[0]) / 2,
                     "hi": z[-1] + (z[1] - z[0]) / 2, "lateral_area": 1.9e-4, "rho_p": 0.0,
                     "snapshots_read": 18.0, "snapshots_used": 8.0,
                     "particles_outside_grid": 0.0, **(extra or {})}.items():
            f.attrs[k] = float(v)


def write_ekm(path, z, t, prof, scenario, attrs, wall, gap=None):
    """z: the cell centres of the first output; gap [nt] (a pressure-held
    wall): the gap of each output, which stretches them; /z has the centres
    of each output (continuum/h5out.c)."""
    scale = np.ones(len(t)) if gap is None else np.asarray(gap, float) / gap[0]
    zt = z[None, :] * scale[:, None]
    with h5py.File(path, "w") as f:
        f.create_dataset("z", data=zt).attrs.create("units", np.bytes_(UNITS["z"]))
        f.create_dataset("t", data=np.asarray(t, float)).attrs.create("units", np.bytes_(UNITS["t"]))
        if gap is not None:
            f.create_dataset("gap", data=np.asarray(gap, float)).attrs.create("units", np.bytes_(UNITS["gap"]))
        rows = [prof(zi, tt) for zi, tt in zip(zt, t)]
        for n in EKM_FIELDS:
            f.create_dataset(n, data=np.array([r[n] for r in rows])).attrs.create(
                "units", np.bytes_(UNITS[n]))
        reg = np.where(np.array([r["phi"] for r in rows]) > 1e-4, 1, 0).astype(np.int32)
        f.create_dataset("regime", data=reg).attrs.create(
            "units", np.bytes_(UNITS["regime"]))
        for k, v in MATERIAL.items():
            f.attrs["material." + k] = float(v)
        for k, v in attrs.items():
            if isinstance(v, str):
                _str(f, k, v)
            else:
                f.attrs[k] = float(v)
        _str(f, "scenario", scenario)
        _str(f, "variant", "full")
        _str(f, "created", "2026-01-01T00:00:00Z")
        f.attrs["stats.wall_time_s"] = float(wall)
        f.attrs["stats.steps"] = 1000.0


# a fitted [material] (ekmcompare fit --ini): the rheology set of ref
FIT_INI = """; [material] fitted by ekmcompare fit --rheology (synthetic)
[material]
rho_p   = 2500
phi_co  = 0.58 ; fitted, SE 0.002
phi_cp  = 0.64
T0      = 3.2 ; fitted, SE 0.3
eta0    = 2.4e-4 ; fitted, SE 2e-5
zeta0   = 1e-4
lambda0 = 3.4e-4
eps0    = 300 ; fitted, SE 20
nu      = 1
A_h     = 200e6
B_h     = 200e6
alpha   = 0
"""


def write_dem_json(path, scenario, engine, point, wall):
    with open(path, "w") as fh:
        json.dump({"scenario": scenario, "engine": engine, "size": "synthetic", "point": point,
                   "particles": 1000, "steps": 35000, "wall_time_s": wall, "status": "ok"}, fh)


def full(prof):
    """Fill the fields a profile function leaves out (rho, vy, mu, I, ...)."""
    def f(z, t):
        r = prof(z, t)
        r.setdefault("vx", np.zeros_like(z))
        r.setdefault("vz", np.zeros_like(z))
        r.setdefault("sxz", np.zeros_like(z))
        r["rho"] = RHO_P * r["phi"]
        r["vy"] = 0.01 * r["vx"]
        with np.errstate(divide="ignore", invalid="ignore"):
            r["mu"] = np.where(r["P"] > 0, np.abs(r["sxz"]) / r["P"], 0.0)
        r["I"] = 0.1 * np.ones_like(z)
        return r
    return f


def chute(theta, dem):
    h, g = 0.04, 9.81
    th = np.radians(theta)

    def prof(z, t):
        inside = (z > 0) & (z < h)
        phi = np.where(inside, 0.58, 0.0) if not dem else \
            0.58 * 0.25 * (1 + np.tanh(z / (0.5 * D))) * (1 - np.tanh((z - h) / D))
        depth = np.clip(h - z, 0, None)
        P = RHO_P * 0.58 * g * np.cos(th) * depth
        return {"phi": phi, "vx": (0.1 if dem else 0.12) * (theta / 24) * (1 - (depth / h) ** 1.5),
                "T": 1e-4 * (1 + depth / h), "P": P, "sxz": P * np.tan(th), "szz": -P}
    return full(prof)


def filling(dem):
    def prof(z, t):
        hb = 0.04 * min(t, 0.5) / 0.5
        bed = 0.5 * (1 - np.tanh((z - hb) / D)) if hb > 0 else np.zeros_like(z)
        stream = 0.05 * (z > hb) * (t < 0.5)
        phi = 0.62 * bed + stream if dem else 0.6 * bed + stream
        P = RHO_P * 0.6 * 9.81 * np.clip(hb - z, 0, None)
        return {"phi": phi, "vz": np.where(z > hb, -1.0 - 2 * (0.1 - z), 0.0) * (t < 0.5),
                "T": 1e-3 * stream + 1e-6, "P": P, "szz": -P}
    return full(prof)


def shear_cell(dem):
    gap, v = 0.042, 0.42

    def prof(z, t):
        phi = 0.56 * (z > 0) * (z < gap)
        return {"phi": phi, "vx": v * np.clip(z / gap, 0, 1), "T": 2e-4 * np.ones_like(z),
                "P": 100.0 * (phi > 0), "sxz": 40.0 * (phi > 0), "szz": -100.0 * (phi > 0)}
    return full(prof)


def simple_shear(phi, rate, dem):
    m = MATERIAL
    g = 1 / (1 - phi / m["phi_cp"])
    P = m["rho_p"] * g * 2 * m["eta0"] * rate ** 2 / (3 * m["eps0"]) * (5.0 if dem else 1.0)

    def prof(z, t):
        return {"phi": phi * np.ones_like(z), "vx": rate * (z - 0.01),
                "T": 2 * m["eta0"] * rate ** 2 / (3 * phi * m["eps0"]) * np.ones_like(z),
                "P": P * np.ones_like(z), "sxz": 0.45 * P * np.ones_like(z),
                "szz": -P * np.ones_like(z)}
    return full(prof)


def simple_shear_p(P, rate):
    """The DEM side of a pressure-controlled point: made-up mu(I), phi(I)."""
    I = rate * D / np.sqrt(P / RHO_P)
    phi = 0.60 - 0.2 * I

    def prof(z, t):
        return {"phi": phi * np.ones_like(z), "vx": rate * (z - 0.01),
                "T": 1e-4 * rate * np.ones_like(z), "P": P * np.ones_like(z),
                "sxz": (0.38 + 0.3 * I) * P * np.ones_like(z), "szz": -P * np.ones_like(z)}
    return full(prof)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--layout", choices=("ref", "smoke"), required=True)
    ap.add_argument("--fields", required=True, help="build/generated/fields.json (the field schema)")
    ap.add_argument("out")
    a = ap.parse_args()
    UNITS.update(load_units(a.fields))
    rng = np.random.default_rng(1)
    ref = a.layout == "ref"
    rows = []
    zc = lambda lo, hi, n: lo + (np.arange(n) + 0.5) * (hi - lo) / n  # noqa: E731

    def point_dir(s, p):
        d = os.path.join(a.out, s, p) if p else os.path.join(a.out, s)
        os.makedirs(d, exist_ok=True)
        return d

    def add_rows(s, p, engines, pvars):
        # the score files, with the options they were made with (as
        # `ekmcompare score` writes them; the figures read shift and EKM time
        # matching from there)
        for e in engines:
            with open(os.path.join(point_dir(s, p), "score_ekm_%s.json" % e), "w") as fh:
                json.dump({"dem": "cg_%s.h5" % e, "ekm": "ekm.h5",
                           "options": {"fields": FIELDS[s].split(","), "ekm_time": EKM_TIME[s],
                                       "shift_m": 0.0},
                           "fields": {}}, fh, indent=1)
        for f in FIELDS[s].split(","):
            row = {"scenario": s, "point": p, "vars": pvars, "field": f}
            for e in ("liggghts", "lammps"):
                row["ekm_vs_" + e] = {"status": "ok", "rel_l2": 0.1, "noise_normalised": 3.0,
                                      "points": 40} if e in engines else {"status": "n/a"}
            row["liggghts_vs_lammps"] = {"status": "ok", "rel_l2": 0.01, "noise_normalised": 1.0} \
                if len(engines) == 2 else {"status": "n/a"}
            rows.append(row)

    both = ("liggghts", "lammps")
    # chute: steady profiles, sweep over the angle (ref)
    for p in (["theta22", "theta24"] if ref else [""]):
        theta = float(p[5:]) if p else 24.0
        d = point_dir("chute", p)
        for e in both:
            write_cg(os.path.join(d, "cg_%s.h5" % e), zc(-0.004, 0.06, 64), [0.27],
                     chute(theta, True), rng, e)
            write_dem_json(os.path.join(d, "dem_%s.json" % e), "chute", e, p, 6.0)
        write_ekm(os.path.join(d, "ekm.h5"), zc(0, 0.06, 60), np.linspace(0, 5, 11), chute(theta, False),
                  "chute", {"gravity.angle": theta, "gravity.magnitude": 9.81, "top.type": "free",
                            "bottom.type": "wall", "domain.length": 0.06, "domain.cells": 60.0}, 0.7)
        if ref:   # the run with the fitted rheology set: another made-up profile
            write_ekm(os.path.join(d, "ekm_rheology.h5"), zc(0, 0.06, 60), np.linspace(0, 5, 11),
                      chute(theta + 2, False), "chute",
                      {"gravity.angle": theta, "gravity.magnitude": 9.81, "top.type": "free",
                       "bottom.type": "wall", "domain.length": 0.06, "domain.cells": 60.0}, 0.8)
        add_rows("chute", p, both, {"theta": "%g" % theta})
    # filling: a time series
    d = point_dir("filling", "")
    tdem = [0.04, 0.14, 0.24, 0.34, 0.44, 0.54, 0.64, 0.74, 0.84, 0.94, 1.0]
    for e in both:
        write_cg(os.path.join(d, "cg_%s.h5" % e), zc(0, 0.1, 100), tdem, filling(True), rng, e)
        write_dem_json(os.path.join(d, "dem_%s.json" % e), "filling", e, "", 12.0)
    write_ekm(os.path.join(d, "ekm.h5"), zc(0, 0.1, 50), np.linspace(0, 1, 51), filling(False),
              "filling", {"top.type": "inflow", "top.t_stop": 0.5, "top.phi": 0.05, "top.w": -1.0,
                          "domain.length": 0.1, "domain.cells": 50.0}, 0.09)
    add_rows("filling", "", both, {})
    # shear_cell
    d = point_dir("shear_cell", "")
    for e in both:
        write_cg(os.path.join(d, "cg_%s.h5" % e), zc(-0.004, 0.087, 92), [0.45], shear_cell(True), rng, e)
        write_dem_json(os.path.join(d, "dem_%s.json" % e), "shear_cell", e, "", 9.0)
    # the top wall held at its pressure: the gap closes from 42 to 38.4 mm
    write_ekm(os.path.join(d, "ekm.h5"), zc(0, 0.042, 42), np.linspace(0, 100, 11), shear_cell(False),
              "shear_cell", {"top.velocity": 0.42, "bottom.velocity": 0.0, "domain.length": 0.042,
                             "domain.cells": 42.0, "top.pressure": 100.0}, 1.4,
              gap=0.0384 + 0.0036 * np.exp(-np.linspace(0, 100, 11) / 10))
    if ref:
        write_ekm(os.path.join(d, "ekm_rheology.h5"), zc(0, 0.042, 42), np.linspace(0, 100, 11),
                  shear_cell(True), "shear_cell", {"top.velocity": 0.42, "bottom.velocity": 0.0,
                                                   "domain.length": 0.042, "domain.cells": 42.0}, 1.5)
    add_rows("shear_cell", "", both, {})
    # simple_shear: LAMMPS only; sweep over phi and rate (ref)
    pts = ["phi0.50-rate5", "phi0.50-rate10", "phi0.53-rate5", "phi0.53-rate10"] if ref else [""]
    for p in pts:
        phi, rate = (float(p[3:7]), float(p.split("rate")[1])) if p else (0.55, 10.0)
        d = point_dir("simple_shear", p)
        write_cg(os.path.join(d, "cg_lammps.h5"), zc(0, 0.02, 20), [0.175],
                 simple_shear(phi, rate, True), rng, "lammps")
        write_dem_json(os.path.join(d, "dem_lammps.json"), "simple_shear", "lammps", p, 2.9)
        v = rate * 0.02 / 2
        write_ekm(os.path.join(d, "ekm.h5"), zc(0, 0.02, 20), np.linspace(0, 50, 11),
                  simple_shear(phi, rate, False), "simple_shear",
                  {"initial.phi": phi, "top.velocity": v, "bottom.velocity": -v,
                   "domain.length": 0.02, "domain.cells": 20.0, "gravity.magnitude": 0.0}, 0.06)
        # the point's sweep variables as the scenario reader prints them
        add_rows("simple_shear", p, ("lammps",), {"phi": "%.2f" % phi, "rate": "%g" % rate})
    # simple_shear_p: LAMMPS only; pressures x rates (ref); the EKM at a fixed
    # gap ([initial] phi 0.55) at the point's rate
    for p in (["p10-rate10", "p100-rate10"] if ref else [""]):
        P, rate = (float(p[1:].split("-")[0]), float(p.split("rate")[1])) if p else (100.0, 10.0)
        d = point_dir("simple_shear_p", p)
        write_cg(os.path.join(d, "cg_lammps.h5"), zc(0.0029, 0.0169, 7), [0.175],
                 simple_shear_p(P, rate), rng, "lammps")
        write_dem_json(os.path.join(d, "dem_lammps.json"), "simple_shear_p", "lammps", p, 4.2)
        v = rate * 0.02 / 2
        write_ekm(os.path.join(d, "ekm.h5"), zc(0, 0.02, 20), np.linspace(0, 50, 11),
                  simple_shear(0.55, rate, False), "simple_shear_p",
                  {"initial.phi": 0.55, "top.velocity": v, "bottom.velocity": -v,
                   "domain.length": 0.02, "domain.cells": 20.0, "gravity.magnitude": 0.0}, 0.06)
        add_rows("simple_shear_p", p, ("lammps",), {"pressure": "%g" % P, "rate": "%g" % rate})
    if ref:
        here = os.path.dirname(os.path.abspath(__file__))
        with open(os.path.join(here, "calibration.json")) as fh:
            cal = fh.read()
        with open(os.path.join(a.out, "calibration.json"), "w") as fh:
            fh.write(cal)
        for name in ("rheology", "chute"):
            os.makedirs(os.path.join(a.out, "calibration", name), exist_ok=True)
            with open(os.path.join(a.out, "calibration", name, "fit.json"), "w") as fh:
                json.dump({"params": {}, "chi2_dof": 1.0}, fh)
        with open(os.path.join(a.out, "calibration", "rheology", "fit.ini"), "w") as fh:
            fh.write(FIT_INI)
    with open(os.path.join(a.out, "scores.json"), "w") as fh:
        json.dump({"size": a.layout, "engines": ["liggghts", "lammps"], "created": "2026-01-01T00:00:00Z",
                   "code_version": "synthetic", "rows": rows}, fh, indent=1)


if __name__ == "__main__":
    main()
