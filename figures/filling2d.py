#!/usr/bin/python3
"""filling2d.py: figures and numbers of a 2D box filling run (thesis Section
4.6.2, scenarios/thesis_filling_2d.ini; thesis Figures 4.9-4.12).

    /usr/bin/python3 figures/filling2d.py RUN.h5 OUTDIR [--point X Z]

RUN.h5 is the output of `ekm run` on a 2D scenario (docs/output-format.md,
"2D runs": /x, /z, /t, /phi /vx /vz /T /P /sxx /szz /sxz as [nt][nz][nx]
and /regime, x fastest; every scenario key a root attribute). The
monitoring point (default x = 0.04 m, z = 0.05 m, the thesis's "middle of
the box") selects the cell that contains it. Writes into OUTDIR, each file
under a temporary name renamed when complete:

  filling2d_history.pdf/.png  at the monitoring cell against time (thesis
                              Figs 4.9-4.11): phi; T with its quasi-static
                              value (log); |v| (log); the shear and
                              compression rates (log); P_Y, sigma_s and
                              |P - P_eq| (log); sigma_s/P. The inflow stop
                              (top.t_stop) and the bed's arrival marked
  filling2d_fields.pdf/.png   the last frame over the box (thesis Fig.
                              4.12): phi, T (log colour scale), |v| (log),
                              P and sigma_s/P, true aspect
  filling2d_captions.txt      the two captions (definitions, provenance)
  filling2d.json              the monitoring cell; at the bed's arrival,
                              the inflow stop and the last frame: T, |v|,
                              rates, P_Y, sigma_s/P, ...; the largest T in
                              2.5-3.0 s; the final bed's T range, sigma_s/P
                              mean and median, bed height. Each number
                              {"value", "units"}; null with a "reason" when
                              it cannot be computed (never NaN); the input's
                              provenance

Definitions (also written into filling2d.json, "definitions"):
- monitoring cell: the cell (ix, iz) = (floor(X/dx), floor(Z/dz)) that
  contains the point (the upper cell on a face, the last cell on the far
  wall); every history value is that cell's, nothing is interpolated;
- rates from the cell-centred velocities by central differences with the
  neighbouring cells, d/dx f = (f[k+1] - f[k-1]) / (2 dx) (one-sided with
  the one neighbour next to a wall), the neighbours' output values as they
  are (an empty cell's velocity is 0): shear rate |dvx/dz + dvz/dx| (the
  engineering rate, 2 |kappa_xz|: |du/dz| in simple shear), compression
  rate |div v| = |dvx/dx + dvz/dz| (the thesis's |kappa_ll|);
- P_Y = rho_p T0 (phi - phi_co) g(phi) above phi_co, 0 below, and P_K =
  rho_p phi T g(phi), g = 1/(1 - phi/phi_cp): law/model.c,
  ekm_pressure_yield and ekm_pressure_kinetic, with the run's material.*;
  P_eq = P_K + P_Y, the viscous pressure P - P_eq (= -zeta div v in a
  flowing cell, the thesis's P~ = -zeta kappa_ll; in a solid cell the
  hypoplastic stress's departure from P_eq at the cell's frozen T);
- sigma_s = sqrt(s:s), s the stress deviator (docs/model-notes.md section 1, the
  thesis's invariant; sqrt(J2) = sigma_s/sqrt(2)), of plane strain with the
  out-of-plane stress syy = -3 P - sxx - szz: the output's P is -(sxx +
  syy + szz)/3 in every wet cell (continuum/twod/fields2d.c: model.h's
  ekm_stress_plane in a flowing cell, syy its isotropic part; the state's
  syy in a solid one), so s = (sxx + P, syy + P, szz + P, sxz) and
  sigma_s^2 = (sxx + P)^2 + (szz + P)^2 + (sxx + szz + 2P)^2 + 2 sxz^2;
- quasi-static T: the local balance of viscous heating and dissipation at
  the cell's phi and rates (model.h: ekm_temperature_source_coeffs_plane and
  ekm_source_balance, the variant's heating; thesis Fig. 4.11), the
  positive root of phi eps0 T^2 + (phi eps0 nu Y - 2/3 Ka) T - 2/3 Kb = 0,
  Ka = eta0 s2 + zeta0 div^2, Kb = Y (nu eta0 s2 + zeta0 div^2), Y = T0
  (phi - phi_co)_+/phi, s2 = shear^2 (thesis variant; full: + 2 (exx^2 +
  ezz^2 - div^2/3)), from the central-difference rates above;
- key times: the bed's arrival (the first frame whose phi at the monitoring
  cell exceeds phi_co), the inflow stop (the frame nearest to top.t_stop,
  the earlier on a tie) and the last frame;
- T peak: the largest T at the monitoring cell over the frames with 2.5 s
  <= t <= 3.0 s where it is not empty (the thesis: a peak when the inflow
  stops at 2.55 s);
  local_maximum: larger than both neighbouring frames;
- bed cells: phi > 0.5; bed height: the number of rows with phi > 0.5 in
  the middle column times dz (the mean over the two middle columns when
  the number of columns is even);
- empty cells (regime 0) are left out of the figures and of every number.

Everything is read and checked before anything is drawn: a missing or
malformed input stops with one line on stderr. Exit status
(docs/exit-codes.md): 0 done; 1 usage (also a --point outside the box);
2 bad input (a 1D run, a dataset or attribute missing or not as
expected); 3 the input missing or unreadable, or an output that cannot be
written; 7 a Python package missing. SIGTERM, SIGHUP and SIGINT end it
with 128+N after removing the temporary being written. Output is
deterministic (no dates: the JSON's "created" is the run's).
"""
import argparse
import json
import math
import os
import signal
import sys

sys.dont_write_bytecode = True          # no __pycache__ in the source tree
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import common as C  # noqa: E402
from pile2d import ArgParser, q, num, public, write_atomic, provenance_line  # noqa: E402
from pile2d import _inch_axes  # noqa: E402

PROG = "filling2d.py"
USAGE = 1
UNAVAILABLE = 7

DEFAULT_POINT = (0.04, 0.05)   # m: the thesis's monitoring point, "the middle of the box"
BED_PHI = 0.5                  # a bed cell: phi above this
PEAK_WINDOW = (2.5, 3.0)       # s: where the thesis shows T's peak (inflow stop at 2.55 s)
THESIS_FRICTION = 1.0 / 7.0    # the thesis's sigma_s/P at the end of the filling (Section 4.6.2)
FIELDS = ("phi", "vx", "vz", "T", "P", "sxx", "szz", "sxz")
UNITS = {"x": "m", "z": "m", "t": "s", "phi": "1", "vx": "m/s", "vz": "m/s", "T": "m^2/s^2",
         "P": "Pa", "sxx": "Pa", "szz": "Pa", "sxz": "Pa"}
MATERIAL = {"rho_p": "kg/m^3", "phi_co": "1", "phi_cp": "1", "T0": "m^2/s^2", "eta0": "m",
            "zeta0": "m", "eps0": "1/m", "nu": "1"}
REGIME = {0: "empty", 1: "kinetic", 2: "dense", 3: "solid"}


def point_arg(s):
    try:
        v = float(s)
    except ValueError:
        raise argparse.ArgumentTypeError("expected a coordinate in m, got %r" % s)
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError("expected a finite coordinate in m, got %r" % s)
    return v


# --- input ------------------------------------------------------------------------

class Run(C.Run2D):
    """The 2D run: grid, times, the fields [nt][nz][nx], regime, material,
    the inflow stop, provenance."""

    WHAT = "the 2D ekm run to plot"

    def __init__(self, path):
        import numpy as np
        self.path = path
        r = C.rel(path)
        with C._open(path, self.WHAT) as f:
            d = C.read_run2d(f, path, FIELDS + ("regime",), dict(UNITS), self.WHAT, PROG)
            self.attrs = d["attrs"]
            self.mat = {}
            for k in MATERIAL:
                self.mat[k] = C._attr(f, path, "material." + k,
                                      "a material constant of P_Y, P_K and the quasi-static T")
        m = self.mat
        if not (m["rho_p"] > 0 and 0 < m["phi_co"] < m["phi_cp"] < 1 and m["T0"] > 0 and m["eps0"] > 0
                and m["eta0"] > 0 and m["zeta0"] > 0 and m["nu"] > 0):
            raise C.InputError("%s: material %s: expected 0 < phi_co < phi_cp < 1 and positive "
                               "constants" % (r, ", ".join("%s = %g" % kv for kv in m.items())))
        self.variant = self.text("model.variant") or self.text("variant")
        if self.variant not in ("thesis", "full"):
            raise C.InputError("%s: root attribute 'model.variant': expected \"thesis\" or \"full\", got "
                               "%r (the stress and heating of the quasi-static T)" % (r, self.variant))
        ts = self.attrs.get("top.t_stop")
        try:
            ts = float(ts) if ts is not None else None
        except (TypeError, ValueError):
            raise C.InputError("%s: root attribute 'top.t_stop': expected a number, got %r" % (r, ts))
        self.t_stop = ts                     # None: not in the file; inf: never
        self.x, self.z, self.t = d["x"], d["z"], d["t"]
        nz, nx = self.z.size, self.x.size
        for n in FIELDS + ("regime",):
            setattr(self, n, d[n])
        self.dx, self.dz = 2 * self.x[0], 2 * self.z[0]
        for n, c, h in (("x", self.x, self.dx), ("z", self.z, self.dz)):
            if not (h > 0 and np.allclose(c, (np.arange(c.size) + 0.5) * h, rtol=1e-9, atol=1e-12 * h)):
                raise C.InputError("%s: dataset /%s: expected the cell centres (i + 1/2) d%s of a "
                                   "uniform grid from 0" % (r, n, n))
        if nx < 2 or nz < 2:
            raise C.InputError("%s: %d x %d cells: %s needs at least two cells each way (the rates' "
                               "differences; a 2D run, [domain] cells_x > 1)" % (r, nx, nz, PROG))
        wet = self.regime > 0
        if np.any(wet & (self.phi >= m["phi_cp"])):
            i, j, k = np.argwhere(wet & (self.phi >= m["phi_cp"]))[0]
            raise C.InputError("%s: dataset /phi: %g >= phi_cp = %g at frame %d, cell (ix %d, iz %d)"
                               % (r, self.phi[i, j, k], m["phi_cp"], i, k, j))
        self.width, self.height = nx * self.dx, nz * self.dz

    def cell(self, px, pz):
        """(ix, iz) of the cell containing the point; None outside the box."""
        if not (0 <= px <= self.width and 0 <= pz <= self.height):
            return None
        return (min(int(math.floor(px / self.dx)), self.x.size - 1),
                min(int(math.floor(pz / self.dz)), self.z.size - 1))


# --- the model's formulas (law/model.c), vectorised -----------------------------

def g_factor(m, phi):
    """ekm_g: 1/(1 - phi/phi_cp)."""
    return 1.0 / (1.0 - phi / m["phi_cp"])


def pressure_yield(m, phi):
    """ekm_pressure_yield: rho_p T0 (phi - phi_co) g above phi_co, else 0."""
    import numpy as np
    phi = np.asarray(phi, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        py = m["rho_p"] * m["T0"] * (phi - m["phi_co"]) * g_factor(m, phi)
    return np.where(phi > m["phi_co"], py, 0.0)


def pressure_kinetic(m, phi, T):
    """ekm_pressure_kinetic: rho_p phi T g."""
    return m["rho_p"] * phi * T * g_factor(m, phi)


def temperature_quasi_static(m, variant, phi, shear, exx, ezz):
    """T where the local source vanishes (ekm_temperature_source_coeffs_plane,
    ekm_source_balance; the common factor rho_p g cancels); 0 where phi <= 0."""
    import numpy as np
    phi = np.asarray(phi, dtype=float)
    div = exx + ezz
    d2 = div * div
    s2 = shear * shear
    if variant != "thesis":
        s2 = s2 + 2.0 * (exx * exx + ezz * ezz - d2 / 3.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        Y = np.where(phi > m["phi_co"], m["T0"] * (phi - m["phi_co"]) / phi, 0.0)
        A = phi * m["eps0"]
        ka = 2.0 / 3.0 * (m["eta0"] * s2 + m["zeta0"] * d2)
        ky = 2.0 / 3.0 * Y * (m["nu"] * m["eta0"] * s2 + m["zeta0"] * d2)
        B = A * m["nu"] * Y - ka
        Cc = -ky
        disc = np.sqrt(B * B - 4.0 * A * Cc)
        pos = np.where(disc + B > 0.0, -2.0 * Cc / (B + disc), 0.0)
        neg = (-B + disc) / (2.0 * A)
        T = np.where(B > 0.0, pos, neg)
    return np.where(phi > 0.0, T, 0.0)


def sigma_s(P, sxx, szz, sxz):
    """sqrt(s:s) of the plane-strain deviator with syy = -3P - sxx - szz."""
    import numpy as np
    dxx, dzz = sxx + P, szz + P
    return np.sqrt(dxx * dxx + dzz * dzz + (dxx + dzz) ** 2 + 2.0 * sxz * sxz)


# --- analysis ---------------------------------------------------------------------

def derivative(f, idx, h, axis_len):
    """The derivative at index idx along one cell axis (spacing h, axis_len
    cells): central, one-sided next to a wall; f(index) -> the field's
    series [nt] at that index (the other index fixed)."""
    if 0 < idx < axis_len - 1:
        return (f(idx + 1) - f(idx - 1)) / (2.0 * h)
    if idx == 0:
        return (f(1) - f(0)) / h
    return (f(idx) - f(idx - 1)) / h


class History:
    """The monitoring cell's series [nt]; empty frames (regime 0) NaN."""

    def __init__(self, run, ix, iz):
        import numpy as np
        m = run.mat
        self.ix, self.iz = ix, iz
        s = (slice(None), iz, ix)
        self.regime = run.regime[s]
        wet = self.regime > 0
        self.wet = wet

        def mask(a):
            return np.where(wet, a, np.nan)
        self.phi = run.phi[s].copy()
        self.T = mask(run.T[s])
        self.speed = mask(np.hypot(run.vx[s], run.vz[s]))
        dvx_dz = derivative(lambda j: run.vx[:, j, ix], iz, run.dz, run.z.size)
        dvz_dz = derivative(lambda j: run.vz[:, j, ix], iz, run.dz, run.z.size)
        dvx_dx = derivative(lambda k: run.vx[:, iz, k], ix, run.dx, run.x.size)
        dvz_dx = derivative(lambda k: run.vz[:, iz, k], ix, run.dx, run.x.size)
        self.shear = mask(np.abs(dvx_dz + dvz_dx))
        self.comp = mask(np.abs(dvx_dx + dvz_dz))
        self.T_qs = mask(temperature_quasi_static(m, run.variant, self.phi, dvx_dz + dvz_dx, dvx_dx,
                                                  dvz_dz))
        self.P = mask(run.P[s])
        self.P_Y = mask(pressure_yield(m, self.phi))
        self.P_K = mask(pressure_kinetic(m, self.phi, run.T[s]))
        self.P_visc = self.P - self.P_K - self.P_Y
        self.sigma_s = mask(sigma_s(run.P[s], run.sxx[s], run.szz[s], run.sxz[s]))
        with np.errstate(divide="ignore", invalid="ignore"):
            self.ratio = np.where(self.P > 0, self.sigma_s / self.P, np.nan)


def middle_columns(run):
    nx = run.x.size
    return [nx // 2] if nx % 2 else [nx // 2 - 1, nx // 2]


def bed_height(run, i):
    import numpy as np
    cols = middle_columns(run)
    rows = [int(np.count_nonzero(run.phi[i][:, k] > BED_PHI)) for k in cols]
    return float(np.mean(rows)) * run.dz, rows


def at_frame(run, h, i, why_frame=None):
    """The monitoring cell's numbers at frame i."""
    out = {"time": q(num(run.t[i]), "s"), "frame": q(int(i), "1 (index into /t)"),
           "regime": REGIME[int(h.regime[i])], "phi": q(num(h.phi[i]), "1")}
    empty = "the monitoring cell is empty (regime 0) at t = %g s" % run.t[i]
    for key, arr, units in (("T", h.T, "m^2/s^2"), ("T_quasi_static", h.T_qs, "m^2/s^2"),
                            ("speed", h.speed, "m/s"), ("shear_rate", h.shear, "1/s"),
                            ("compression_rate", h.comp, "1/s"), ("P", h.P, "Pa"),
                            ("P_Y", h.P_Y, "Pa"), ("P_K", h.P_K, "Pa"),
                            ("P_viscous", h.P_visc, "Pa"), ("sigma_s", h.sigma_s, "Pa")):
        v = num(arr[i])
        out[key] = q(v, units, None if v is not None else empty)
    v = num(h.ratio[i])
    out["sigma_s_over_P"] = q(v, "1", None if v is not None else
                              (empty if not h.wet[i] else "P = %.3g Pa is not positive" % h.P[i]))
    hb, rows = bed_height(run, i)
    out["bed_height"] = q(num(hb), "m", rows=q(rows, "1"))
    return out


def null_frame(why):
    return {"time": q(None, "s", why), "frame": q(None, "1 (index into /t)", why)}


def analyse(run, ix, iz, point):
    """Everything of filling2d.json, plus the figures' private entries."""
    import numpy as np
    h = History(run, ix, iz)
    m = run.mat
    js = {}
    js["monitoring_cell"] = {
        "point": q([num(point[0]), num(point[1])], "m"),
        "ix": q(ix, "1 (index into /x)"), "iz": q(iz, "1 (index into /z)"),
        "centre": q([num(run.x[ix]), num(run.z[iz])], "m"),
        "x_range": q([num(ix * run.dx), num((ix + 1) * run.dx)], "m"),
        "z_range": q([num(iz * run.dz), num((iz + 1) * run.dz)], "m")}
    # key times
    keys = {}
    above = np.nonzero(h.phi > m["phi_co"])[0]
    ib = int(above[0]) if above.size else None
    if ib is None:
        keys["bed_arrival"] = null_frame("phi at the monitoring cell never exceeds phi_co = %g (largest "
                                         "%.4g)" % (m["phi_co"], float(h.phi.max())))
    else:
        keys["bed_arrival"] = at_frame(run, h, ib)
    ts = run.t_stop
    istop = None
    if ts is None:
        keys["inflow_stop"] = null_frame("no root attribute top.t_stop (the scenario has no inflow "
                                         "stop)")
    elif not math.isfinite(ts):
        keys["inflow_stop"] = null_frame("top.t_stop = %g: the inflow never stops" % ts)
    elif ts > run.t[-1] + 0.5 * (run.t[-1] - run.t[-2] if run.t.size > 1 else 0):
        keys["inflow_stop"] = null_frame("top.t_stop = %g s is after the last frame (t = %g s)"
                                         % (ts, run.t[-1]))
    else:
        istop = run.nearest(ts)
        keys["inflow_stop"] = dict(at_frame(run, h, istop), t_stop=q(num(ts), "s"))
    il = run.t.size - 1
    keys["last_frame"] = at_frame(run, h, il)
    js["key_times"] = keys
    # the T peak in the window
    lo, hi = PEAK_WINDOW
    tol = 1e-9 * max(1.0, hi)
    win = np.nonzero((run.t >= lo - tol) & (run.t <= hi + tol) & h.wet)[0]
    if win.size == 0:
        js["T_peak"] = {"value": None, "units": "m^2/s^2", "window": q([lo, hi], "s"),
                        "reason": "no frame with the monitoring cell wet in %g..%g s (run %g..%g s)"
                                  % (lo, hi, run.t[0], run.t[-1])}
    else:
        ip = int(win[np.nanargmax(h.T[win])])
        nb = [h.T[i] for i in (ip - 1, ip + 1) if 0 <= i < run.t.size]
        local = bool(len(nb) == 2 and all(np.isfinite(nb)) and h.T[ip] > max(nb))
        js["T_peak"] = q(num(h.T[ip]), "m^2/s^2", window=q([lo, hi], "s"), time=q(num(run.t[ip]), "s"),
                         frame=q(ip, "1 (index into /t)"), local_maximum=local,
                         frames_in_window=q(int(win.size), "1"))
    # the final bed
    js["final"] = final_bed(run, il)
    js["_history"], js["_bed_arrival"], js["_stop"] = h, ib, istop
    return js


def final_bed(run, i):
    import numpy as np
    phi = run.phi[i]
    bed = (phi > BED_PHI) & (run.regime[i] > 0)
    out = {"time": q(num(run.t[i]), "s"), "frame": q(int(i), "1 (index into /t)"),
           "bed_cells": q(int(bed.sum()), "1")}
    hb, rows = bed_height(run, i)
    out["bed_height"] = q(num(hb), "m", rows=q(rows, "1"),
                          columns=q(middle_columns(run), "1 (index into /x)"))
    if not bed.any():
        why = "no bed cell (phi > %g) at the last frame (largest phi %.4g)" % (BED_PHI, float(phi.max()))
        out["T_range"] = q(None, "m^2/s^2", why)
        out["sigma_s_over_P_mean"] = q(None, "1", why)
        out["sigma_s_over_P_median"] = q(None, "1", why)
        out["P_max"] = q(None, "Pa", why)
        return out
    T = run.T[i][bed]
    out["T_range"] = q([num(T.min()), num(T.max())], "m^2/s^2")
    P = run.P[i]
    ss = sigma_s(P, run.sxx[i], run.szz[i], run.sxz[i])
    ok = bed & (P > 0)
    if ok.any():
        r = ss[ok] / P[ok]
        out["sigma_s_over_P_mean"] = q(num(r.mean()), "1", cells=q(int(ok.sum()), "1"))
        out["sigma_s_over_P_median"] = q(num(np.median(r)), "1", cells=q(int(ok.sum()), "1"))
    else:
        why = "no bed cell with P > 0"
        out["sigma_s_over_P_mean"] = q(None, "1", why)
        out["sigma_s_over_P_median"] = q(None, "1", why)
    j, k = np.unravel_index(int(np.argmax(np.where(bed, P, -np.inf))), P.shape)
    out["P_max"] = q(num(P[j, k]), "Pa", x=q(num(run.x[k]), "m"), z=q(num(run.z[j]), "m"),
                     scaled=q(num(P[j, k] / run.mat["rho_p"]), "Pa/(kg m^-3)"))
    return out


DEFINITIONS = {
    "monitoring_cell": "the cell (ix, iz) = (floor(X/dx), floor(Z/dz)) containing the point (X, Z) "
                       "(the upper cell on a face, the last on the far wall); its own values, not "
                       "interpolated",
    "rates": "from the cell-centred velocities by central differences with the neighbouring cells "
             "((f[k+1] - f[k-1]) / (2 dx); one-sided at a wall), the neighbours' output values as they "
             "are (0 in an empty cell): shear_rate = |dvx/dz + dvz/dx| (2 |kappa_xz|, |du/dz| in simple "
             "shear), compression_rate = |div v| = |dvx/dx + dvz/dz| (the thesis's |kappa_ll|)",
    "speed": "|v| = sqrt(vx^2 + vz^2) at the cell centre",
    "P_Y": "rho_p T0 (phi - phi_co) / (1 - phi/phi_cp) above phi_co, 0 below (law/model.c "
           "ekm_pressure_yield, the run's material.*)",
    "P_K": "rho_p phi T / (1 - phi/phi_cp) (law/model.c ekm_pressure_kinetic)",
    "P_viscous": "P - P_eq, P_eq = P_K + P_Y: -zeta div v in a flowing cell (the thesis's P~ = "
                 "-zeta kappa_ll); in a solid cell the hypoplastic stress's departure from P_eq at its "
                 "frozen T",
    "sigma_s": "sqrt(s:s), s the deviator of (sxx, syy, szz, sxz) (docs/model-notes.md section 1; sqrt(J2) = "
               "sigma_s / sqrt(2)), syy = -3 P - sxx - szz: the output P is -(sxx + syy + szz)/3 in "
               "every wet cell (continuum/twod/fields2d.c; ekm_stress_plane's isotropic part in a "
               "flowing cell, the state's syy in a solid one)",
    "sigma_s_over_P": "sigma_s / P, where P > 0",
    "T_quasi_static": "the local balance of viscous heating and dissipation at the cell's phi and "
                      "central-difference rates: positive root of phi eps0 T^2 + (phi eps0 nu Y - 2/3 "
                      "Ka) T - 2/3 Kb = 0, Ka = eta0 s2 + zeta0 div^2, Kb = Y (nu eta0 s2 + zeta0 "
                      "div^2), Y = T0 (phi - phi_co)_+ / phi, s2 = shear_rate^2 (thesis variant; full: "
                      "+ 2 (exx^2 + ezz^2 - div^2/3)) (model.h ekm_temperature_source_coeffs_plane, "
                      "ekm_source_balance)",
    "bed_arrival": "the first frame whose phi at the monitoring cell exceeds material.phi_co",
    "inflow_stop": "the frame nearest to top.t_stop (the earlier on a tie)",
    "T_peak": "the largest T at the monitoring cell over the frames with 2.5 s <= t <= 3.0 s where it "
              "is not empty; local_maximum: larger than both neighbouring frames",
    "bed_cell": "phi > 0.5 (and not empty)",
    "bed_height": "the number of rows with phi > 0.5 in the middle column times dz (the mean over "
                  "the two middle columns for an even number of columns; rows: each column's count)",
    "T_range": "smallest and largest T over the bed cells of the last frame (a solid cell's T is "
               "frozen when it turns solid)",
    "P_max": "the largest P over the bed cells of the last frame, at its cell centre; scaled: P/rho_p "
             "(the thesis's pressure scaled with the bulk density, Pa/(kg m^-3))",
    "empty": "cells of regime 0 (phi < numerics.phi_dry) are left out of the figures and the numbers",
}


# --- figures ----------------------------------------------------------------------

def _mark_times(ax, run, res):
    if res["_stop"] is not None:
        ax.axvline(run.t_stop, color="#D55E00", lw=0.7, ls="-", zorder=1)
    if res["_bed_arrival"] is not None:
        ax.axvline(run.t[res["_bed_arrival"]], color="0.45", lw=0.7, ls=":", zorder=1)


def _panel_label(ax, s):
    ax.text(0.02, 0.95, s, transform=ax.transAxes, ha="left", va="top", fontsize=7,
            bbox=dict(fc="white", ec="none", alpha=0.8, pad=0.8))


def _pos(a):
    """a with its values <= 0 as NaN (left out of a log axis, not clipped to its bottom)."""
    import numpy as np
    return np.where(np.isfinite(a) & (a > 0), a, np.nan)


def _log_limits(ax, arrays, below=1.0, above=1.0):
    """y limits of a log panel: the data's range widened by the given decades
    (room for the panel label and the legend)."""
    import numpy as np
    v = np.concatenate([np.asarray(a)[np.isfinite(a) & (np.asarray(a) > 0)] for a in arrays])
    if v.size:
        ax.set_ylim(10 ** (math.floor(math.log10(v.min())) - below),
                    10 ** (math.ceil(math.log10(v.max())) + above))


def history_figure(run, res, writer, meta):
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.lines import Line2D
    h = res["_history"]
    t = run.t
    W, H = C.PAGE_W, 5.8
    fig = plt.figure(figsize=(W, H))
    left, right, bottom, top, hgap, vgap = 0.55, 0.12, 0.42, 0.4, 1.05, 0.12
    pw = (W - left - right - hgap) / 2
    ph = (H - bottom - top - 2 * vgap) / 3
    axes = []
    for r in range(3):
        for c in range(2):
            axes.append(_inch_axes(fig, W, H, left + c * (pw + hgap), bottom + (2 - r) * (ph + vgap),
                                   pw, ph))
    a_phi, a_T, a_v, a_rate, a_st, a_mu = axes
    black, blue, green, red = "black", "#0072B2", "#009E73", "#D55E00"
    lw = 0.9
    # (a) phi
    a_phi.plot(t, np.where(h.wet, h.phi, np.nan), color=black, lw=lw)
    a_phi.axhline(run.mat["phi_co"], color="0.5", lw=0.6, ls="--")
    a_phi.text(0.03, run.mat["phi_co"] - 0.01, r"$\phi_{co}$", transform=a_phi.get_yaxis_transform(),
               va="top", ha="left", fontsize=6.5, color="0.4")
    a_phi.set_ylabel(r"$\phi$ [-]")
    a_phi.set_ylim(0, max(0.7, float(np.nanmax(h.phi)) * 1.1))
    # (b) T and its quasi-static value (thesis Fig. 4.11)
    a_T.semilogy(t, _pos(h.T), color=black, lw=lw, label=r"$T$")
    a_T.semilogy(t, _pos(h.T_qs), color=blue, lw=lw, ls="--", label=r"$T$ quasi-static")
    a_T.set_ylabel(r"$T$ [m$^2$/s$^2$]")
    _log_limits(a_T, [_pos(h.T), _pos(h.T_qs)], 0.5, 2.5)
    a_T.legend(loc="upper right", fontsize=6.5)
    # (c) |v|
    a_v.semilogy(t, _pos(h.speed), color=black, lw=lw)
    a_v.set_ylabel(r"$|v|$ [m/s]")
    _log_limits(a_v, [_pos(h.speed)], 0.5, 1.0)
    # (d) rates
    a_rate.semilogy(t, _pos(h.shear), color=black, lw=lw, label=r"shear $|\partial_z v_x + \partial_x v_z|$")
    a_rate.semilogy(t, _pos(h.comp), color=green, lw=lw, ls="--", label=r"compression $|\nabla\cdot v|$")
    a_rate.set_ylabel(r"rate [s$^{-1}$]")
    _log_limits(a_rate, [_pos(h.shear), _pos(h.comp)], 0.5, 1.0)
    a_rate.legend(loc="lower left", fontsize=6.5)
    # (e) stresses (thesis Fig. 4.10)
    a_st.semilogy(t, _pos(h.P_Y), color=black, lw=lw, label=r"$P_Y$")
    a_st.semilogy(t, _pos(h.sigma_s), color=blue, lw=lw, ls="--", label=r"$\sigma_s$")
    pv = h.P_visc
    a_st.semilogy(t, _pos(np.abs(pv)), color=red, lw=0.8, ls="-.", label=r"$|P - P_{eq}|$")
    neg = np.isfinite(pv) & (pv < 0)
    if neg.any():
        a_st.plot(t[neg], -pv[neg], ls="none", marker="o", ms=2.0, mfc="white", mec=red, mew=0.5)
    a_st.set_ylabel(r"stress [Pa]")
    _log_limits(a_st, [_pos(h.P_Y), _pos(h.sigma_s), _pos(np.abs(pv))], 2.0, 1.0)
    rb = run.mat["rho_p"]
    sec = a_st.secondary_yaxis("right", functions=(lambda v: v / rb, lambda v: v * rb))
    sec.set_ylabel(r"stress/$\rho_b$ [Pa/(kg m$^{-3}$)]", fontsize=7)
    sec.tick_params(labelsize=6)
    a_st.tick_params(axis="y", which="both", right=False)
    handles, labels = a_st.get_legend_handles_labels()
    if neg.any():
        handles.append(Line2D([], [], ls="none", marker="o", ms=2.5, mfc="white", mec=red, mew=0.5))
        labels.append(r"$P - P_{eq} < 0$")
    a_st.legend(handles, labels, loc="lower right", fontsize=6, ncol=2)
    # (f) sigma_s/P
    a_mu.semilogy(t, _pos(h.ratio), color=black, lw=lw)
    a_mu.axhline(THESIS_FRICTION, color="0.5", lw=0.6, ls="--")
    a_mu.text(0.03, THESIS_FRICTION * 0.85, "thesis 1/7", transform=a_mu.get_yaxis_transform(), va="top",
              ha="left", fontsize=6.5, color="0.4")
    a_mu.set_ylabel(r"$\sigma_s/P$ [-]")
    _log_limits(a_mu, [_pos(h.ratio), np.array([THESIS_FRICTION])], 0.5, 1.0)
    names = "abcdef"
    for n, ax in enumerate(axes):
        ax.set_xlim(t[0], t[-1])
        _mark_times(ax, run, res)
        _panel_label(ax, "(%s)" % names[n])
        if n >= 4:
            ax.set_xlabel(r"$t$ [s]")
        else:
            ax.tick_params(labelbottom=False)
    # the key of the vertical lines and the cell, above the panels
    key = [Line2D([], [], color="0.45", lw=0.7, ls=":"), Line2D([], [], color="#D55E00", lw=0.7)]
    lab = [r"bed arrives ($\phi > \phi_{co}$)", "inflow stops"]
    cell = r"cell ($i_x$ %d, $i_z$ %d) at $x$ = %.4g m, $z$ = %.4g m" % (h.ix, h.iz, run.x[h.ix],
                                                                          run.z[h.iz])
    fig.legend(key, lab, loc="upper right", bbox_to_anchor=(1 - right / W, 1 - 0.02 / H), ncol=2,
               fontsize=7)
    fig.text(left / W, 1 - 0.1 / H, cell, ha="left", va="top", fontsize=7)
    writer.save(fig, "filling2d_history", meta)


def fields_figure(run, res, writer, meta):
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib import colors, ticker
    i = run.t.size - 1
    wet = run.regime[i] > 0
    phi = np.where(wet, run.phi[i], np.nan)
    T = np.where(wet & (run.T[i] > 0), run.T[i], np.nan)
    sp = np.hypot(run.vx[i], run.vz[i])
    sp = np.where(wet & (sp > 0), sp, np.nan)
    P = np.where(wet, run.P[i], np.nan)
    ss = sigma_s(run.P[i], run.sxx[i], run.szz[i], run.sxz[i])
    with np.errstate(divide="ignore", invalid="ignore"):
        mu = np.where(wet & (run.P[i] > 0), ss / run.P[i], np.nan)
    xe = np.arange(run.x.size + 1) * run.dx
    ze = np.arange(run.z.size + 1) * run.dz

    def lognorm(a):
        f = a[np.isfinite(a)]
        if f.size == 0:
            return colors.LogNorm(1e-3, 1)
        lo, hi = float(f.min()), float(f.max())
        return colors.LogNorm(lo, hi if hi > lo else lo * 10)

    def linnorm(a, lo=None):
        f = a[np.isfinite(a)]
        if f.size == 0:
            return colors.Normalize(0, 1)
        lo = float(f.min()) if lo is None else lo
        hi = float(f.max())
        return colors.Normalize(lo, hi if hi > lo else lo + 1)

    # sigma_s/P on the bed's scale: the dilute cells above it (P near 0) reach
    # tens, drawn in the scale's top colour (the bar's arrow)
    bed = run.phi[i] > BED_PHI
    mu_bed = np.where(bed, mu, np.nan)
    mu_norm = linnorm(mu_bed if np.isfinite(mu_bed).any() else mu, 0.0)
    mu_ext = "max" if np.nanmax(np.where(np.isfinite(mu), mu, -1.0)) > mu_norm.vmax else "neither"
    panels = [(phi, linnorm(phi, 0.0), "viridis", r"$\phi$ [-]", "neither"),
              (T, lognorm(T), "inferno", r"$T$ [m$^2$/s$^2$]", "neither"),
              (sp, lognorm(sp), "cividis", r"$|v|$ [m/s]", "neither"),
              (P, linnorm(P, 0.0), "magma_r", r"$P$ [Pa]", "neither"),
              (mu, mu_norm, "PuBuGn", r"$\sigma_s/P$ [-]", mu_ext)]
    n = len(panels)
    W = C.PAGE_W
    left, right, gap = 0.42, 0.12, 0.28
    pw = (W - left - right - (n - 1) * gap) / n
    ph = pw * run.height / run.width
    bottom, cbh, cbgap, top = 0.36, 0.07, 0.1, 0.5
    H = bottom + ph + cbgap + cbh + top
    fig = plt.figure(figsize=(W, H))
    for c, (a, norm, cmap, label, extend) in enumerate(panels):
        x0 = left + c * (pw + gap)
        ax = _inch_axes(fig, W, H, x0, bottom, pw, ph)
        cm = plt.get_cmap(cmap).copy()
        cm.set_bad("0.9")
        im = ax.pcolormesh(xe, ze, a, cmap=cm, norm=norm, rasterized=True)
        ax.set_xlim(0, run.width)
        ax.set_ylim(0, run.height)
        ax.set_aspect("equal")
        ax.plot(run.x[res["_history"].ix], run.z[res["_history"].iz], marker="+", color="white", ms=5,
                mew=1.4)
        ax.plot(run.x[res["_history"].ix], run.z[res["_history"].iz], marker="+", color="black", ms=4,
                mew=0.6)
        ax.set_xlabel(r"$x$ [m]")
        ax.xaxis.set_major_locator(ticker.FixedLocator([0.0, 0.5 * run.width, run.width]))
        ax.xaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _p: "%g" % float("%.3g" % v)))
        if c == 0:
            ax.set_ylabel(r"$z$ [m]", labelpad=2)
        else:
            ax.tick_params(labelleft=False)
        ax.text(0.04, 0.985, "(%s)" % "abcde"[c], transform=ax.transAxes, ha="left", va="top",
                fontsize=7, bbox=dict(fc="white", ec="none", alpha=0.8, pad=0.8))
        cax = _inch_axes(fig, W, H, x0, bottom + ph + cbgap, pw, cbh)
        cb = fig.colorbar(im, cax=cax, orientation="horizontal", extend=extend)
        cb.set_label(label, fontsize=7, labelpad=2)
        cax.xaxis.set_label_position("top")
        cax.xaxis.set_ticks_position("top")
        cb.ax.tick_params(direction="out", labelsize=6, bottom=False, top=True)
        if isinstance(norm, colors.LogNorm):
            cb.ax.xaxis.set_major_locator(ticker.LogLocator(numticks=4))
        else:
            cb.ax.xaxis.set_major_locator(ticker.MaxNLocator(3))
    fig.text(0.5 * left / W, 1 - 0.03 / H, r"$t$ = %g s (the last frame)" % float("%.4g" % run.t[i]),
             ha="left", va="top", fontsize=7)
    writer.save(fig, "filling2d_fields", meta)


# --- captions ---------------------------------------------------------------------

def captions(run, res, prov):
    h = res["_history"]
    stop = ("the inflow stop top.t_stop = %g s (orange line)" % run.t_stop if res["_stop"] is not None
            else "no inflow stop in the run")
    arr = ("the bed's arrival, the first frame with phi > phi_co = %g there, t = %g s (grey dotted)"
           % (run.mat["phi_co"], run.t[res["_bed_arrival"]]) if res["_bed_arrival"] is not None
           else "phi never exceeds phi_co there")
    hist = ("filling2d_history: the box filling (thesis Figures 4.9-4.11) at the monitoring cell "
            "(ix %d, iz %d; centre x = %.4g m, z = %.4g m), against time t in s: (a) solid volume "
            "fraction phi; (b) granular temperature T and its quasi-static value (the local balance of "
            "viscous heating and dissipation at the cell's phi and rates, %s variant) in m^2/s^2; (c) "
            "speed |v| in m/s; (d) shear rate |dvx/dz + dvz/dx| and compression rate |div v| in 1/s, "
            "central differences of the cell-centred velocities with the neighbouring cells; (e) yield "
            "pressure P_Y (law/model.c), shear stress sigma_s = sqrt(s:s) of the plane-strain "
            "deviator (syy = -3P - sxx - szz) and viscous pressure |P - P_eq|, P_eq = P_K + P_Y (open "
            "circles where P - P_eq < 0), in Pa, right axis scaled with the bulk density rho_b = "
            "rho_p = %g kg/m^3; (f) sigma_s/P, the thesis's 1/7 dashed. Marked: %s; %s. Empty frames "
            "(regime 0) left out. %s."
            % (h.ix, h.iz, run.x[h.ix], run.z[h.iz], run.variant, run.mat["rho_p"], arr, stop,
               provenance_line(prov)))
    fld = ("filling2d_fields: the box at the end of the filling, t = %g s (the last frame; thesis Figure "
           "4.12): (a) phi, (b) T in m^2/s^2 (log colour scale), (c) speed |v| in m/s (log), (d) "
           "pressure P in Pa (P/rho_b = P/%g in Pa/(kg m^-3)), (e) sigma_s/P; empty cells light grey, "
           "the monitoring cell marked +. x and z in m, equal aspect. %s."
           % (run.t[-1], run.mat["rho_p"], provenance_line(prov)))
    return hist, fld


def main(argv=None):
    def stop(signum, _frame):
        raise SystemExit(128 + signum)
    for sig in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT):
        signal.signal(sig, stop)
    ap = ArgParser(prog=PROG, description="Figures and numbers of a 2D box filling run "
                                          "(thesis Section 4.6.2).")
    ap.add_argument("run", help="the 2D ekm output (RUN.h5)")
    ap.add_argument("outdir", help="folder for the figures and filling2d.json")
    ap.add_argument("--point", nargs=2, type=point_arg, metavar=("X", "Z"), default=list(DEFAULT_POINT),
                    help="the monitoring point [m] (default 0.04 0.05); the cell containing it is used")
    a = ap.parse_args(argv)
    try:
        import numpy  # noqa: F401
        import h5py  # noqa: F401
        import matplotlib  # noqa: F401
    except ImportError as e:
        print("%s: %s (install scripts/deps/figures.txt; use /usr/bin/python3)" % (PROG, e),
              file=sys.stderr)
        return UNAVAILABLE
    try:
        run = Run(a.run)
        cell = run.cell(*a.point)
        if cell is None:
            print("%s: --point %g %g: outside the box (x 0..%g m, z 0..%g m) of %s"
                  % (PROG, a.point[0], a.point[1], run.width, run.height, C.rel(a.run)), file=sys.stderr)
            return USAGE
        res = analyse(run, cell[0], cell[1], a.point)
    except C.InputError as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return e.status
    prov = run.provenance()
    cap_h, cap_f = captions(run, res, prov)
    subject = provenance_line(prov)
    m = run.mat
    js = {"program": "figures/filling2d.py", "input": prov, "definitions": DEFINITIONS,
          "material": {k: q(num(v), MATERIAL[k]) for k, v in m.items()},
          "variant": run.variant,
          "grid": {"dx": q(num(run.dx), "m"), "dz": q(num(run.dz), "m"),
                   "nx": q(int(run.x.size), "1"), "nz": q(int(run.z.size), "1"),
                   "width": q(num(run.width), "m"), "height": q(num(run.height), "m")}}
    js.update(public(res))
    try:
        text = json.dumps(js, indent=1, allow_nan=False) + "\n"
    except ValueError as e:      # a NaN slipped through: a bug, not an input problem
        print("%s: internal error: %s" % (PROG, e), file=sys.stderr)
        return 5
    C.style()
    w = C.Writer(a.outdir)
    try:
        os.makedirs(a.outdir, exist_ok=True)
        history_figure(run, res, w, {"Title": "Box filling: the monitoring cell's history (filling2d.py)",
                                     "Subject": subject, "Keywords": cap_h})
        fields_figure(run, res, w, {"Title": "Box filling: the fields at the end (filling2d.py)",
                                    "Subject": subject, "Keywords": cap_f})
        write_atomic(os.path.join(a.outdir, "filling2d_captions.txt"), cap_h + "\n\n" + cap_f + "\n")
        write_atomic(os.path.join(a.outdir, "filling2d.json"), text)
    except OSError as e:
        print("%s: %s: cannot write (%s)" % (PROG, C.rel(e.filename or a.outdir), e.strerror or e),
              file=sys.stderr)
        return C.IO_ERROR
    print("%s: %s: filling2d_history, filling2d_fields (.pdf, .png), filling2d_captions.txt, "
          "filling2d.json" % (PROG, a.outdir))
    return 0


if __name__ == "__main__":
    sys.exit(main())
