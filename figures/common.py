"""common.py: style, loading and checking of a campaign results folder, and
atomic figure output for figures/make_figures.py.

A results folder RES (docs/campaign.md, workflow/Snakefile):
    RES/scores.json                  the score table: scenarios, sweep points,
                                     scored fields, engines (the index here)
    RES/S[/P]/cg_<engine>.h5         coarse-grained DEM profiles (docs/compare.md)
    RES/S[/P]/ekm.h5                 the EKM run (docs/output-format.md)
    RES/S[/P]/dem_<engine>.json      the DEM run manifest (wall_time_s)
    RES/S[/P]/score_ekm_<engine>.json   the score: its "options" give the
                                     coordinate shift and the EKM time matching
                                     the comparison was made with
The figures read results only (no scenario file): shift and time matching
from the scores' options, units from the HDF5 datasets' `units` attributes.
Everything is read and checked before any figure is drawn: a missing file
or dataset stops the program with one line naming it (InputError, whose
status is the exit status of docs/exit-codes.md: 3 for a missing or
unreadable file, 2 for a file that is there but not as expected).
"""
import json
import os
import re

import numpy as np

PROG = "make_figures.py"
ENGINES = ("liggghts", "lammps")
ENGINE_LABEL = {"liggghts": "DEM LIGGGHTS", "lammps": "DEM LAMMPS"}
EKM_LABEL = "EKM"
# Okabe-Ito colours (colour-blind safe); EKM black
ENGINE_COLOUR = {"liggghts": "#0072B2", "lammps": "#D55E00"}
EKM_COLOUR = "black"
POINT_COLOURS = ["#0072B2", "#009E73", "#D55E00", "#CC79A7", "#E69F00", "#56B4E9"]

COLUMN_W = 3.4   # in, single journal column
PAGE_W = 7.0     # in, two columns

# a DEM bin is plotted for v and T only where phi is above this (empty bins
# are NaN anyway; the dilute edge is noise); the same for EKM cells
PHI_VISIBLE = 1e-3

FIELD_LABEL = {
    "phi": r"$\phi$",
    "vx": r"$v_x$",
    "vz": r"$v_z$",
    "T": r"$T$",
    "P": r"$P$",
    "sxz": r"$\sigma_{xz}$",
    "szz": r"$\sigma_{zz}$",
    "sxx": r"$\sigma_{xx}$",
}
FIELD_ORDER = ("phi", "vx", "vz", "T", "P", "sxz", "szz", "sxx")


BAD_INPUT = 2     # exit statuses, docs/exit-codes.md
IO_ERROR = 3


class InputError(Exception):
    """A missing or malformed input: one line for stderr, and the exit
    status (BAD_INPUT: there but not as expected; IO_ERROR: a file missing
    or unreadable)."""

    def __init__(self, message, status=BAD_INPUT):
        super().__init__(message)
        self.status = status


def style():
    """Journal style: Agg, 8 pt, no titles, deterministic PDF."""
    import matplotlib
    matplotlib.use("Agg")
    matplotlib.rcParams.update({
        "font.size": 8,
        "axes.labelsize": 8,
        "xtick.labelsize": 7,
        "ytick.labelsize": 7,
        "legend.fontsize": 7,
        "legend.frameon": False,
        "axes.linewidth": 0.6,
        "xtick.major.width": 0.6,
        "ytick.major.width": 0.6,
        "xtick.minor.width": 0.4,
        "ytick.minor.width": 0.4,
        "xtick.direction": "in",
        "ytick.direction": "in",
        "xtick.top": True,
        "ytick.right": True,
        "lines.linewidth": 1.0,
        "lines.markersize": 3.5,
        "errorbar.capsize": 1.5,
        "pdf.fonttype": 42,
        "ps.fonttype": 42,
        "savefig.dpi": 300,
        "figure.dpi": 100,
        "axes.formatter.use_mathtext": True,
        "svg.hashsalt": "ekmbench",
    })


def unit_label(units):
    """The `units` attribute of a dataset as an axis unit: '1' (dimensionless)
    is none, powers become superscripts ('m^2/s^2' -> 'm$^2$/s$^2$')."""
    if units == "1":
        return ""
    return re.sub(r"\^(-?[0-9]+)", lambda m: "$^%s$" % (m.group(1) if len(m.group(1)) == 1
                                                         else "{%s}" % m.group(1)), units)


def field_axis_label(name, units, scale_exp=0):
    """'T [10^-4 m^2/s^2]' style label, with the scale factor folded in;
    units: the dataset's `units` attribute."""
    unit = unit_label(units)
    if scale_exp:
        unit = (r"$10^{%d}$ " % scale_exp) + unit
    return FIELD_LABEL[name] + (" [%s]" % unit if unit else "")


def scale_exponent(values):
    """Power of ten to divide by so the largest |value| is between 1 and
    1e3; 0 when it already is (or there is nothing finite)."""
    a = np.asarray(values, dtype=float)
    a = np.abs(a[np.isfinite(a)])
    if a.size == 0 or a.max() == 0:
        return 0
    e = int(np.floor(np.log10(a.max())))
    return e if (e < -2 or e > 3) else 0


# --- paths and messages -------------------------------------------------------

def rel(path):
    """A path as the user gave it (relative to the working directory when
    that is shorter): messages name files the way the user can find them."""
    r = os.path.relpath(path)
    return r if not r.startswith("../..") else path


def missing(path, what):
    return InputError("%s: missing (%s)" % (rel(path), what), IO_ERROR)


# --- scores.json: the index ------------------------------------------------------

class Point:
    """One scenario x sweep point: its folder and the data found there."""

    def __init__(self, scenario, name, folder):
        self.scenario = scenario
        self.name = name            # '' for a single case
        self.folder = folder
        self.status = {}            # engine -> 'ok' | 'missing' (score status)
        self.cg = {}                # engine -> CgData
        self.dem_json = {}          # engine -> dict
        self.ekm = None             # EkmRun of the thesis set (ekm.h5)
        self.ekm_sets = {}          # parameter set -> EkmRun (ekm_<set>.h5), name order
        self.shift = {}             # engine -> shift [m] of its score's options
        self.vars = {}              # sweep variable -> value as the reader resolved it
        self.where = ""             # "RES/scores.json: rows[i]" of its first row

    def label(self):
        return self.name if self.name else "-"


class Scenario:
    def __init__(self, name):
        self.name = name
        self.fields = []            # scored fields, table order
        self.points = []            # Point, table order
        self.engines = []           # engines that can run it (not n/a)
        self.steady = True          # scored with ekm_time = last
        self.units = {}             # field -> `units` attribute of its datasets
        self.twod = False           # scored by ekmcompare score2d: maps (Map2D), not profiles

    def velocity(self):
        return "vz" if "vz" in self.fields else "vx"

    def plotted_fields(self):
        """The profile fields of figure 1: the scored ones, in a fixed order."""
        return [f for f in FIELD_ORDER if f in self.fields]


def read_json(path, what):
    if not os.path.isfile(path):
        raise missing(path, what)
    try:
        with open(path) as fh:
            return json.load(fh)
    except OSError as e:
        raise InputError("%s: cannot read (%s): %s" % (rel(path), what, e.strerror or e), IO_ERROR)
    except ValueError as e:
        raise InputError("%s: cannot read as JSON (%s): %s" % (rel(path), what, e))


def load_index(res):
    """Scenarios, points, fields and engines from RES/scores.json."""
    path = os.path.join(res, "scores.json")
    js = read_json(path, "the campaign's score table, which lists the scenarios, "
                         "sweep points and engines to plot")
    if not isinstance(js, dict) or not isinstance(js.get("rows"), list):
        raise InputError("%s: expected an object with a 'rows' list (the score table)" % rel(path))
    scen = {}
    for i, row in enumerate(js["rows"]):
        try:
            s, p, f = row["scenario"], row["point"], row["field"]
            st = {e: row["ekm_vs_" + e]["status"] for e in ENGINES}
        except (KeyError, TypeError):
            raise InputError("%s: rows[%d]: expected scenario, point, field, ekm_vs_liggghts.status "
                             "and ekm_vs_lammps.status" % (rel(path), i))
        if not (isinstance(s, str) and re.fullmatch(r"[A-Za-z0-9_.-]+", s)
                and isinstance(p, str) and re.fullmatch(r"[A-Za-z0-9_.-]*", p)):
            raise InputError("%s: rows[%d]: bad scenario or point name %r/%r" % (rel(path), i, s, p))
        sc = scen.setdefault(s, Scenario(s))
        if f not in sc.fields:
            if f not in FIELD_LABEL:
                raise InputError("%s: rows[%d]: unknown field %r" % (rel(path), i, f))
            sc.fields.append(f)
        pt = next((q for q in sc.points if q.name == p), None)
        if pt is None:
            pt = Point(s, p, os.path.join(res, s, p) if p else os.path.join(res, s))
            v = row.get("vars", {})
            if not (isinstance(v, dict) and all(isinstance(x, str) for x in v.values())):
                raise InputError("%s: rows[%d]: 'vars': expected an object of strings (the point's "
                                 "sweep variables), got %r" % (rel(path), i, v))
            pt.vars = v
            pt.where = "%s: rows[%d]" % (rel(path), i)
            sc.points.append(pt)
        for e, v in st.items():
            if v != "n/a":
                pt.status[e] = "ok" if (v == "ok" and pt.status.get(e, "ok") == "ok") else "missing"
                if e not in sc.engines:
                    sc.engines.append(e)
    sc_list = list(scen.values())
    for sc in sc_list:
        sc.engines = [e for e in ENGINES if e in sc.engines]
    return sc_list


# --- score files: the options a comparison was made with -------------------------

def score_options(path, what):
    """(shift [m], ekm_time) of a score file: its "options" (written by
    `ekmcompare score`: fields, ekm_time, shift_m)."""
    js = read_json(path, what)
    opts = js.get("options") if isinstance(js, dict) else None
    if not isinstance(opts, dict):
        raise InputError("%s: 'options': missing (the shift and EKM time matching the score was "
                         "made with; written by ekmcompare score)" % rel(path))
    shift = opts.get("shift_m")
    if not isinstance(shift, (int, float)) or isinstance(shift, bool) or not np.isfinite(shift):
        raise InputError("%s: 'options.shift_m': expected a number, got %r" % (rel(path), shift))
    etime = opts.get("ekm_time")
    if etime not in ("last", "interp"):
        raise InputError("%s: 'options.ekm_time': expected \"last\" or \"interp\", got %r"
                         % (rel(path), etime))
    return float(shift), etime


# --- HDF5 -------------------------------------------------------------------------

def _attr(f, path, name, what, kind=float):
    if name not in f.attrs:
        raise InputError("%s: root attribute '%s': missing (%s)" % (rel(path), name, what))
    v = f.attrs[name]
    if isinstance(v, bytes):
        v = v.decode()
    if kind is float:
        try:
            v = float(np.asarray(v).reshape(-1)[0])
        except (TypeError, ValueError, IndexError):
            raise InputError("%s: root attribute '%s': expected a number, got %r" % (rel(path), name, v))
    return v


def _open(path, what):
    import h5py
    if not os.path.isfile(path):
        raise missing(path, what)
    if not os.access(path, os.R_OK):
        raise InputError("%s: cannot read (%s): permission denied" % (rel(path), what), IO_ERROR)
    try:
        return h5py.File(path, "r")
    except OSError as e:
        raise InputError("%s: cannot read as HDF5 (%s): %s" % (rel(path), what, e))


class Run2D:
    """What the readers of a 2D run (figures/pile2d.py, filling2d.py) share;
    a subclass sets path, attrs (read_run2d's) and t."""

    def text(self, key):
        v = self.attrs.get(key)
        return v if isinstance(v, str) else None

    def provenance(self):
        return {"file": os.path.abspath(self.path),
                "scenario": self.text("scenario") or self.text("scenario.name"),
                "scenario_file": self.text("scenario_file"),
                "code_version": self.text("code_version"),
                "created": self.text("created")}

    def nearest(self, want):
        """Index of the frame nearest to time want (the earlier on a tie)."""
        return int(np.argmin(np.abs(self.t - want)))


def read_run2d(f, path, fields, units, what, prog):
    """The grid and fields of a 2D ekm run (docs/output-format.md "2D runs")
    open as f: {"x", "z", "t": 1-D arrays, each of fields: [nt][nz][nx]
    ("regime" as int codes 0..3), "attrs": the root attributes (strings
    decoded, one-element arrays as scalars)}; units: the SI unit each
    dataset must have; InputError naming the dataset otherwise."""
    r = rel(path)
    if "x" not in f and "phi" in f and len(f["phi"].shape) == 2:
        raise InputError(
            "%s: dataset /x: missing: a 1D run (/phi is [nt][nz]); %s needs a 2D run "
            "([domain] cells_x > 1, docs/output-format.md \"2D runs\")" % (r, prog))
    d = {}
    for n in ("x", "z", "t"):
        if n not in f:
            raise InputError("%s: dataset /%s: missing (%s)" % (r, n, what))
        a = np.asarray(f[n][()], dtype=float)
        if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)):
            raise InputError("%s: dataset /%s: expected a non-empty 1-D array of finite "
                             "numbers, got shape %s" % (r, n, a.shape))
        d[n] = a
    nt, nz, nx = d["t"].size, d["z"].size, d["x"].size
    for n in fields:
        if n not in f:
            raise InputError("%s: dataset /%s: missing (%s)" % (r, n, what))
        a = np.asarray(f[n][()], dtype=int if n == "regime" else float)
        if a.shape != (nt, nz, nx):
            raise InputError("%s: dataset /%s: expected shape [nt][nz][nx] = (%d, %d, %d), "
                             "got %s" % (r, n, nt, nz, nx, a.shape))
        bad = np.argwhere(~np.isfinite(a)) if n != "regime" else np.argwhere((a < 0) | (a > 3))
        if bad.size:
            i, j, k = bad[0]
            raise InputError("%s: dataset /%s: %s at frame %d, cell (ix %d, iz %d)"
                             % (r, n, "not a finite number" if n != "regime" else
                                "not a regime code 0..3 (%d)" % a[i, j, k], i, k, j))
        d[n] = a
    got = _units(f, path, tuple(units))
    for n, u in units.items():
        if got[n] != u:
            raise InputError("%s: dataset /%s: units %r, expected %r (the axes and the "
                             "model's formulas are in SI)" % (r, n, got[n], u))
    attrs = {}
    for k, v in f.attrs.items():
        if isinstance(v, bytes):
            v = v.decode(errors="replace")
        elif isinstance(v, np.ndarray) and v.size == 1:
            v = v.reshape(-1)[0]
        attrs[k] = v
    d["attrs"] = attrs
    if np.any(np.diff(d["t"]) <= 0):
        raise InputError("%s: dataset /t: output times not increasing" % r)
    return d


def _profiles(f, path, names, what, z_rows=False):
    """z [nz] (z_rows: or [nt][nz], the cell centres of each output: an ekm
    output, docs/output-format.md), t [nt] and the named [nt][nz] datasets,
    checked."""
    out = {}
    for d in ("z", "t"):
        if d not in f:
            raise InputError("%s: dataset /%s: missing (%s)" % (rel(path), d, what))
        a = np.asarray(f[d][()], dtype=float)
        if a.size == 0 or not (a.ndim == 1 or (d == "z" and z_rows and a.ndim == 2)):
            raise InputError("%s: dataset /%s: expected a non-empty %s array, got shape %s"
                             % (rel(path), d, "1-D or [nt][nz]" if d == "z" and z_rows else "1-D", a.shape))
        out[d] = a
    nz, nt = out["z"].shape[-1], out["t"].size
    if out["z"].ndim == 2 and out["z"].shape[0] != nt:
        raise InputError("%s: dataset /z: expected one row of cell centres per output time, shape [nt][nz] = "
                         "(%d, %d), got %s" % (rel(path), nt, nz, out["z"].shape))
    for n in names:
        if n not in f:
            raise InputError("%s: dataset /%s: missing (%s)" % (rel(path), n, what))
        a = np.asarray(f[n][()], dtype=float)
        if a.shape != (nt, nz):
            raise InputError("%s: dataset /%s: expected shape [nt][nz] = (%d, %d), got %s"
                             % (rel(path), n, nt, nz, a.shape))
        out[n] = a
    return out


def _units(f, path, names):
    """name -> the `units` attribute of each dataset."""
    out = {}
    for n in names:
        u = f[n].attrs.get("units")
        if isinstance(u, bytes):
            u = u.decode()
        if not isinstance(u, str):
            raise InputError("%s: dataset /%s: attribute 'units': missing (the axis label)" % (rel(path), n))
        out[n] = u
    return out


class CgData:
    """Coarse-grained DEM profiles (docs/compare.md); shift [m]: added to z to
    put them in the EKM's coordinates (the score's options)."""

    def __init__(self, path, engine, fields, what):
        self.path, self.engine = path, engine
        self.shift = 0.0
        with _open(path, what) as f:
            need = []
            for n in fields:
                need += [n, n + "_se"]
            d = _profiles(f, path, need, what)
            self.units = _units(f, path, fields)
            self.d = _attr(f, path, "mean_diameter", "the grain diameter d that scales z")
        self.z, self.t = d["z"], d["t"]
        self.val = {n: d[n] for n in fields}
        self.se = {n: d[n + "_se"] for n in fields}


class EkmRun:
    """The EKM run (docs/output-format.md): profiles and root attributes;
    zt [nt][nz] the cell centres of each output (a pressure-held wall moves
    them), z those of the last output (the steady state the profiles show)."""

    def __init__(self, path, fields, what):
        self.path = path
        with _open(path, what) as f:
            d = _profiles(f, path, list(fields), what, z_rows=True)
            self.units = _units(f, path, fields)
            self.attrs = {}
            for k, v in f.attrs.items():
                if isinstance(v, bytes):
                    v = v.decode()
                elif isinstance(v, np.ndarray) and v.size == 1:
                    v = v.reshape(-1)[0]
                self.attrs[k] = v
            self.wall_time = _attr(f, path, "stats.wall_time_s", "the EKM wall time for the cost chart")
            gap = None
            if "gap" in f and d["z"].ndim == 1:
                # an output from before /z had a row per output, with a
                # pressure-held top wall: /z was the first output's cell
                # centres, those at output i /z * gap[i] / gap[0]
                # (docs/output-format.md)
                gap = np.asarray(f["gap"][()], dtype=float)
                if gap.shape != d["t"].shape or not np.all(np.isfinite(gap)) or np.any(gap <= 0):
                    raise InputError("%s: dataset /gap: expected one positive gap per output time (%d), got shape %s"
                                     % (rel(path), d["t"].size, gap.shape))
        self.t = d["t"]
        if d["z"].ndim == 2:
            self.zt = d["z"]
        elif gap is not None:
            self.zt = d["z"][None, :] * (gap / gap[0])[:, None]
        else:
            self.zt = np.tile(d["z"], (self.t.size, 1))
        self.z = self.zt[-1]
        self.val = {n: d[n] for n in fields}
        # the top wall (or domain end) of the last output
        if self.z.size > 1:
            self.top = self.z[-1] + 0.5 * (self.z[-1] - self.z[-2])
        else:
            self.top = 2 * self.z[0]

    def number(self, name, what):
        if name not in self.attrs:
            raise InputError("%s: root attribute '%s': missing (%s)" % (rel(self.path), name, what))
        try:
            return float(self.attrs[name])
        except (TypeError, ValueError):
            raise InputError("%s: root attribute '%s': expected a number, got %r"
                             % (rel(self.path), name, self.attrs[name]))

    def at(self, name, t):
        """The field at time t, linear between the bracketing outputs
        (as `ekmcompare score` does); the last output past the end."""
        return self._at(self.val[name], t)

    def z_at(self, t):
        """The cell centres at time t, linear between the bracketing outputs
        as the fields (at) are."""
        return self._at(self.zt, t)

    def _at(self, v, t):
        ts = self.t
        if t >= ts[-1]:
            return v[-1]
        if t <= ts[0]:
            return v[0]
        j = int(np.searchsorted(ts, t))
        w = (t - ts[j - 1]) / (ts[j] - ts[j - 1])
        return (1 - w) * v[j - 1] + w * v[j]


class Map2D:
    """The last frame of a 2D field set, for the maps of a 2D scenario
    (figures/pilemaps.py): a cg 2D output's last window (docs/compare.md,
    stresses negative in compression) or an ekm 2D run's last output
    (docs/output-format.md "2D runs", tension positive). x [nx], z [nz]
    [m], t [s], val[name] [nz][nx] with stresses negated to compression
    positive (as score2d compares them); wall_time [s] for an ekm run (the
    cost chart), None for a cg output."""

    STRESSES = ("sxx", "szz", "sxz")

    def __init__(self, path, fields, what, ekm, group=None, time=None):
        """group: a group of a pile-map file (scripts/dem/pile_map.py,
        results/sandpile/maps-SIZE.h5: x, z and [nz][nx] fields, stresses
        already compression positive, no time: t None); time: the frame
        of an ekm run or cg output at that time [s] (to 1e-9), else the
        last."""
        self.path = path
        if group is not None:
            self._group(path, group, fields, what)
            return
        with _open(path, what) as f:
            for n in ("x", "z", "t"):
                if n not in f:
                    raise InputError("%s: dataset /%s: missing (%s)" % (rel(path), n, what))
            self.x = np.asarray(f["x"][()], dtype=float)
            self.z = np.asarray(f["z"][()], dtype=float)
            t = np.asarray(f["t"][()], dtype=float).reshape(-1)
            if self.x.ndim != 1 or self.z.ndim != 1 or t.size == 0:
                raise InputError("%s: datasets /x, /z, /t: expected 1-D arrays (a 2D output; %s)"
                                 % (rel(path), what))
            i = t.size - 1 if time is None else int(np.argmin(np.abs(t - time)))
            if time is not None and abs(t[i] - time) > 1e-9:
                raise InputError("%s: no output at t = %g s (nearest %g s; %s)" % (rel(path), time, t[i], what))
            self.t = float(t[i])
            shape = (t.size, self.z.size, self.x.size)
            self.val = {}
            for n in fields:
                if n not in f:
                    raise InputError("%s: dataset /%s: missing (%s)" % (rel(path), n, what))
                a = np.asarray(f[n][()], dtype=float)
                if a.shape != shape:
                    raise InputError("%s: dataset /%s: expected shape [nt][nz][nx] = %s (a 2D output), got %s"
                                     % (rel(path), n, shape, a.shape))
                self.val[n] = -a[i] if n in self.STRESSES else a[i]
            self.units = _units(f, path, fields)
            self.wall_time = (_attr(f, path, "stats.wall_time_s", "the EKM wall time for the cost chart")
                              if ekm else None)

    def _group(self, path, group, fields, what):
        with _open(path, what) as f:
            if group not in f:
                raise InputError("%s: group %s: missing (%s)" % (rel(path), group, what))
            g = f[group]
            for n in ("x", "z") + tuple(fields):
                if n not in g:
                    raise InputError("%s: dataset %s/%s: missing (%s)" % (rel(path), group, n, what))
            self.x = np.asarray(g["x"][()], dtype=float)
            self.z = np.asarray(g["z"][()], dtype=float)
            self.t, self.wall_time, self.val, self.units = None, None, {}, {}
            for n in fields:
                a = np.asarray(g[n][()], dtype=float)
                if a.shape != (self.z.size, self.x.size):
                    raise InputError("%s: dataset %s/%s: expected shape [nz][nx] = (%d, %d), got %s"
                                     % (rel(path), group, n, self.z.size, self.x.size, a.shape))
                self.val[n] = a
                u = g[n].attrs.get("units")
                self.units[n] = u.decode() if isinstance(u, bytes) else u


def _manifest(pt, e, st, dj, where, notes):
    """The run manifest dem_<e>.json of a point (its wall time for the cost
    chart) into pt.dem_json: required when the comparison is 'ok', used
    when there for a 'missing' one (a note when it has no wall time)."""
    if not (st == "ok" or os.path.isfile(dj)):
        return
    js = read_json(dj, "the %s run manifest of %s: its wall time for the cost chart" % (ENGINE_LABEL[e], where))
    w = js.get("wall_time_s") if isinstance(js, dict) else None
    if isinstance(w, (int, float)) and not isinstance(w, bool) and w >= 0:
        pt.dem_json[e] = js
    elif st == "missing":
        notes.append("%s: %s has no wall_time_s: left out of the cost chart" % (where, rel(dj)))
    else:
        raise InputError("%s: 'wall_time_s': expected a number >= 0 (the cost chart), got %r" % (rel(dj), w))


def _scored_2d(sc):
    """Whether a scenario is scored in 2D: its score files say `ekmcompare
    score2d`; without one, its cg outputs hold [nt][nz][nx] fields."""
    for pt in sc.points:
        if not os.path.isdir(pt.folder):
            continue
        for f in sorted(os.listdir(pt.folder)):
            if f.startswith("score_") and f.endswith(".json"):
                js = read_json(os.path.join(pt.folder, f), "a score of %s" % sc.name)
                return isinstance(js, dict) and js.get("tool") == "ekmcompare score2d"
    for pt in sc.points:
        for e in ENGINES:
            cg = os.path.join(pt.folder, "cg_%s.h5" % e)
            if os.path.isfile(cg):
                with _open(cg, "a cg output of %s" % sc.name) as f:
                    return "phi" in f and len(f["phi"].shape) == 3
    return False


def _load_maps(sc):
    """A 2D scenario's maps: per point each engine's cg output and the EKM
    runs (thesis and fitted sets), their last frames; the run manifests for
    the cost chart. Returns the notes."""
    notes = []
    fields = sc.plotted_fields()
    for pt in sc.points:
        where = sc.name + (" " + pt.name if pt.name else "")
        for e in sc.engines:
            st = pt.status.get(e)
            if st is None:
                continue
            cg = os.path.join(pt.folder, "cg_%s.h5" % e)
            dj = os.path.join(pt.folder, "dem_%s.json" % e)
            if st == "missing" and not os.path.isfile(cg):
                notes.append("%s: no %s map (%s missing: a failed step): left out" % (where, ENGINE_LABEL[e], rel(cg)))
                continue
            pt.cg[e] = Map2D(cg, fields, "the coarse-grained %s map of %s" % (ENGINE_LABEL[e], where), False)
            _manifest(pt, e, st, dj, where, notes)
        ekm = os.path.join(pt.folder, "ekm.h5")
        if os.path.isfile(ekm) or pt.cg:
            pt.ekm = Map2D(ekm, fields, "the EKM run of %s, drawn beside its DEM maps" % where, True)
            for f in sorted(os.listdir(pt.folder)):
                m = re.fullmatch(r"ekm_([A-Za-z0-9_.-]+)\.h5", f)
                if m:
                    pt.ekm_sets[m.group(1)] = Map2D(os.path.join(pt.folder, f), fields,
                                                    "the EKM run of %s with parameter set %s" % (where, m.group(1)),
                                                    True)
        for src in list(pt.cg.values()) + ([pt.ekm] if pt.ekm is not None else []):
            for n, u in src.units.items():
                sc.units.setdefault(n, u)
    sc.steady = True
    return notes


def load_campaign(res, size):
    """Read and check everything the figures need; returns the scenarios.
    Rules: a comparison scored 'ok' needs its cg_<engine>.h5,
    dem_<engine>.json and score_ekm_<engine>.json (whose options give the
    shift and time matching); a 'missing' one (a failed step) uses the cg
    file if it is there (with the shift of the engine's other scores of the
    scenario; left out when there is none) and is skipped with a note if
    not; any cg file needs the point's ekm.h5. size: the campaign size (the
    folder layout is the same for both)."""
    notes = []
    scenarios = load_index(res)
    for sc in scenarios:
        sc.twod = _scored_2d(sc)
        if sc.twod:
            notes += _load_maps(sc)
            continue
        fields = sc.plotted_fields()
        # the options of every score that exists: engine -> [(shift, ekm_time)]
        opts = {}
        for pt in sc.points:
            for e in sc.engines:
                sj = os.path.join(pt.folder, "score_ekm_%s.json" % e)
                if pt.status.get(e) == "ok" or os.path.isfile(sj):
                    o = score_options(sj, "the score of %s against %s: its options give the shift "
                                          "and EKM time" % (sc.name + (" " + pt.name if pt.name else ""),
                                                            ENGINE_LABEL[e]))
                    opts.setdefault(e, []).append(o)
                    pt.shift[e] = o[0]
        for pt in sc.points:
            where = sc.name + (" " + pt.name if pt.name else "")
            for e in sc.engines:
                st = pt.status.get(e)
                if st is None:
                    continue
                cg = os.path.join(pt.folder, "cg_%s.h5" % e)
                dj = os.path.join(pt.folder, "dem_%s.json" % e)
                name = ENGINE_LABEL[e]
                shift = pt.shift.get(e)
                if shift is None and opts.get(e):
                    shift = opts[e][0][0]
                if st == "missing" and not os.path.isfile(cg):
                    notes.append("%s: no %s profiles (%s missing: a failed step): left out"
                                 % (where, name, rel(cg)))
                elif shift is None:
                    notes.append("%s: no score of %s in the scenario (a failed step), so no "
                                 "shift for %s: left out" % (where, name, rel(cg)))
                else:
                    pt.cg[e] = CgData(cg, e, fields, "the coarse-grained %s profiles of %s, "
                                      "plotted against the EKM" % (name, where))
                    pt.cg[e].shift = shift
                _manifest(pt, e, st, dj, where, notes)
            ekm = os.path.join(pt.folder, "ekm.h5")
            if pt.cg:
                pt.ekm = EkmRun(ekm, fields, "the EKM run of %s, plotted against its DEM profiles "
                                "%s" % (where, " and ".join(rel(c.path) for c in pt.cg.values())))
            elif os.path.isfile(ekm):
                pt.ekm = EkmRun(ekm, fields, "the EKM run of %s" % where)
                notes.append("%s: no DEM profiles: EKM in the cost chart only" % where)
            else:
                notes.append("%s: neither DEM profiles nor an EKM run: left out" % where)
            # the runs with a fitted parameter set (--material
            # RES/calibration/<set>/fit.ini): drawn with the thesis run
            if pt.ekm is not None:
                for f in sorted(os.listdir(pt.folder)):
                    m = re.fullmatch(r"ekm_([A-Za-z0-9_.-]+)\.h5", f)
                    if m:
                        pt.ekm_sets[m.group(1)] = EkmRun(
                            os.path.join(pt.folder, f), fields,
                            "the EKM run of %s with parameter set %s" % (where, m.group(1)))
            for src in list(pt.cg.values()) + ([pt.ekm] if pt.ekm is not None else []):
                for n, u in src.units.items():
                    sc.units.setdefault(n, u)
        # the time matching of the scores (the last engine's, as the table's
        # fields); without any score: steady when the DEM has a single profile
        scored = [opts[e] for e in sc.engines if opts.get(e)]
        if scored:
            sc.steady = scored[-1][0][1] == "last"
        else:
            nts = [c.t.size for p in sc.points for c in p.cg.values()]
            sc.steady = bool(nts) and max(nts) == 1
    return scenarios, notes


# --- output -----------------------------------------------------------------------

class Writer:
    """Saves figures as PDF and PNG under RES/figures/, each under a
    temporary name renamed when complete, and keeps the list."""

    def __init__(self, outdir):
        self.outdir = outdir
        self.written = []

    def save(self, fig, stem, meta=None):
        """meta: document metadata for both files (the PDF's keys: Title,
        Subject, Keywords, ...; the PNG takes them as text chunks), e.g.
        the input's provenance; never a date (deterministic output)."""
        import matplotlib.pyplot as plt
        os.makedirs(self.outdir, exist_ok=True)
        for ext in ("pdf", "png"):
            path = os.path.join(self.outdir, "%s.%s" % (stem, ext))
            tmp = os.path.join(self.outdir, ".%s.%s.tmp" % (stem, ext))
            meta_ext = dict(meta or {})
            if ext == "pdf":
                meta_ext["CreationDate"] = None
            try:
                fig.savefig(tmp, format=ext, dpi=300, metadata=meta_ext)
                os.replace(tmp, path)
            finally:
                if os.path.exists(tmp):
                    os.remove(tmp)
            self.written.append(path)
        plt.close(fig)

    def finish(self, listname="figures.txt"):
        path = os.path.join(self.outdir, listname)
        tmp = os.path.join(self.outdir, "." + listname + ".tmp")
        try:
            with open(tmp, "w") as fh:
                for p in self.written:
                    fh.write(p + "\n")
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
        return path


# --- parameter sets and the EKM's closed-form rheology (ekm homog) ------------------

UNAVAILABLE = 7   # docs/exit-codes.md: a required program is missing
THESIS = "thesis"
# EKM line styles of the parameter sets after the first (thesis: solid);
# colours of the sets where the colour is free (rheology figures, heat map)
SET_DASHES = ["-.", (0, (5, 1.2, 1, 1.2, 1, 1.2)), (0, (1.2, 1.2)), (0, (6, 2))]
SET_COLOURS = ["black", "#009E73", "#CC79A7", "#E69F00", "#56B4E9"]


class ParamSet:
    """An EKM parameter set: `thesis` (the scenario files' own [material])
    or one fitted by the campaign's calibration, whose [material] is
    RES/calibration/<name>/fit.ini (`ekmcompare fit --ini`)."""

    def __init__(self, name, fit_ini=None, closure=None):
        self.name = name
        self.fit_ini = fit_ini      # None: the scenario file's [material]
        self.closure = closure      # None: the scenario file's closure (the EKM's)


def set_style(index):
    """(colour, line style) of the index-th parameter set."""
    dash = "-" if index == 0 else SET_DASHES[(index - 1) % len(SET_DASHES)]
    return SET_COLOURS[index % len(SET_COLOURS)], dash


def load_sets(res):
    """The parameter sets that exist in RES: thesis, then every set named
    in RES/calibration.json (if there is one) or found as a folder
    RES/calibration/<set>/, in that order; a set without its fit.ini is
    left out with a note. Returns (sets, notes)."""
    sets, notes = [ParamSet(THESIS)], []
    names, closures = [], {}
    cal = os.path.join(res, "calibration.json")
    if os.path.isfile(cal):
        js = read_json(cal, "the calibration summary, which names the parameter sets")
        lst = js.get("sets") if isinstance(js, dict) else None
        if not isinstance(lst, list) or not all(isinstance(s, dict) and isinstance(s.get("name"), str)
                                                for s in lst):
            raise InputError("%s: 'sets': expected a list of objects with a 'name'" % rel(cal))
        names = [s["name"] for s in lst if s["name"] != THESIS]
        closures = {s["name"]: s.get("closure") for s in lst}
    folder = os.path.join(res, "calibration")
    if os.path.isdir(folder):
        names += sorted(n for n in os.listdir(folder)
                        if os.path.isdir(os.path.join(folder, n)) and n not in names and n != THESIS)
    for n in names:
        if not re.fullmatch(r"[A-Za-z0-9_.-]+", n):
            raise InputError("%s: bad parameter set name %r" % (rel(cal), n))
        ini = os.path.join(folder, n, "fit.ini")
        if os.path.isfile(ini):
            closure = closures.get(n)
            if closure is not None and not (isinstance(closure, str) and re.fullmatch(r"[a-z0-9_]+", closure)):
                raise InputError("%s: set %s: bad closure %r" % (rel(cal), n, closure))
            sets.append(ParamSet(n, ini, closure))
        else:
            notes.append("parameter set %s: %s missing: left out" % (n, rel(ini)))
    return sets, notes


def default_ekm():
    """build/continuum/ekm of the checkout the figures are in."""
    return os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                        "build", "continuum", "ekm")


def homog(ekm, ini, pset, phis, rates):
    """`ekm homog` (docs/model/law.md): the EKM's steady homogeneous simple
    shear of scenario file ini with the set's material, at the volume
    fractions phis = (lo, hi, n) times the rates [1/s]. Returns the parsed
    JSON ({"material": .., "units": .., "points": [..]})."""
    import subprocess
    if not (os.path.isfile(ekm) and os.access(ekm, os.X_OK)):
        raise InputError("%s: missing (the ekm program, whose `ekm homog` gives the EKM's "
                         "closed-form rheology; build it, or give --ekm)" % rel(ekm), UNAVAILABLE)
    cmd = [ekm, "homog", ini]
    if pset.fit_ini:
        cmd += ["--material", pset.fit_ini]
    if pset.closure:
        cmd += ["--set", "model.closure=" + pset.closure]
    cmd += ["--phi", "%.17g:%.17g:%d" % phis, "--rate", ",".join("%.17g" % r for r in rates), "--json"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        msg = p.stderr.strip().splitlines()
        raise InputError("parameter set %s: ekm homog %s%s: %s" % (
            pset.name, rel(ini), " --material " + rel(pset.fit_ini) if pset.fit_ini else "",
            msg[-1] if msg else "exit status %d" % p.returncode),
            p.returncode if p.returncode in (BAD_INPUT, IO_ERROR) else BAD_INPUT)
    try:
        js = json.loads(p.stdout)
        js["points"], js["material"]
    except (ValueError, KeyError, TypeError):
        raise InputError("parameter set %s: ekm homog: output is not the JSON of docs/model/law.md" % pset.name)
    return js
