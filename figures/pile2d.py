#!/usr/bin/python3
"""pile2d.py: figures and numbers of a 2D sand pile run (thesis Section
4.6.3, scenarios/thesis_sandpile_2d.ini; thesis Figures 4.13-4.19).

    /usr/bin/python3 figures/pile2d.py RUN.h5 OUTDIR [--times 0.5,1,1.5,2,3.5]
                                                     [--base-time 3.5] [--extrema]

RUN.h5 is the output of `ekm run` on a 2D scenario (docs/output-format.md,
"2D runs": /x, /z, /t, /phi and /P as [nt][nz][nx], x fastest). Writes
into OUTDIR, each file under a temporary name renamed when complete:

  pile2d_phi.pdf/.png       phi at the frame nearest to each of --times,
                            on the thesis's two scales: 0..max(phi) of the
                            frame, and 0.59..0.61 (the variations inside
                            the heap)
  pile2d_pressure.pdf/.png  P/rho_b at the frame nearest to --base-time,
                            with the pile's surface and flank fits, and the
                            base profile (bottom row of cells) against x:
                            centre and maxima marked (thesis Figs 4.17-4.18);
                            with --extrema (several sources, thesis Fig.
                            4.20) the inlets' centres (top.inlet_x) and the
                            profile's local maxima and minima instead
  pile2d_captions.txt       the two captions (times used, scales, the
                            definitions below, the input's provenance)
  pile2d.json               the pile's numbers at the base time and at the
                            last frame, each {"value", "units"}; a number
                            that cannot be computed is null with a "reason"
                            (never NaN); the input's provenance

"Scaled with the bulk density" (thesis Figs 4.10, 4.12, 4.17, 4.18): the
thesis gives its material parameters per rho_b with rho_b = 1600 kg/m^3
(Section 4.6.2), the density the project calls rho_p ([material] rho_p,
the factor taken out of every material constant: docs/model/law.md, "Units and
conventions"). So the plotted pressure is P / rho_p [Pa/(kg m^-3) = m^2/s^2]
with the run's material.rho_p, not P / (rho_p phi).

Definitions (also written into pile2d.json, "definitions"):
- bed cell: phi > phi_s = phi_co / 2 (half the cross-over volume fraction,
  the run's material.phi_co: the heap packs near phi_co, the falling jet
  is far below it once it has left the inlet);
- surface height h(x) of a column: the top of the contiguous bed cells
  from the bottom cell up, where phi crosses phi_s, linear between that
  cell's centre and the one above (the top face of the cell for a sharp
  edge); 0 where the bottom cell is not a bed cell. Bed cells above a gap
  (the jet, a grain cloud) do not count. Pile height H = max h;
- apex (centre): the top columns are those whose h is within 1% of a
  cell of H; the centre x_c is their mean x, and the centre columns the
  one or two columns nearest to x_c (the two middle columns of a pile
  symmetric on an even number of columns; the middle of a flat top);
- bed kind: "none" (no bed cell in the bottom row), "pile" (a flank line
  fitted on at least one side), "layer" (a bed without flanks: a flat
  layer, where the numbers of the pile's shape are null);
- flank slopes: least-squares line h(x) through the columns on each side
  of x_c whose h is between 20% and 80% of H (leaving out the rounded apex
  and the toe), leaving out the two columns next to each side wall; at
  least 3 columns, else null. Angle = atan of the slope, positive when the
  surface rises towards the apex; "se" its standard error from the fit's
  residuals; "resolution" the angle a height error of one cell (dz) across
  the fitted extent makes: the grid's resolution of the angle;
- phi under the apex vs the flanks: mean phi of the centre column(s) and of
  the flank-fit columns over the same rows (the rows where both have bed
  cells below their surface cell), the topmost bed cell of each column (partly filled, the
  surface) left out;
- base pressure: P of the bottom row of cells. P(centre): mean over the
  centre column(s). Maxima: the largest value under the pile (bottom cell a
  bed cell) at x <= x_c (left) and at x >= x_c (right), at the cell
  centre (resolution dx); P(max) the larger of the two;
- dip: P(max) - P(centre) > 3 sigma, sigma the cell-to-cell noise of the
  base profile under the pile: 1.4826 median(|d3|) / sqrt(20), d3 = P[k+2]
  - 3 P[k+1] + 3 P[k] - P[k-1] the third differences (zero for a profile
  quadratic over four cells, sqrt(20) times the standard deviation of white
  noise; the median, robust to the few kinks: the maxima, the toes),
  floored at 1e-9 P(max) (rounding); null when the pile's base is under
  6 cells;
- base extrema (several sources): the local maxima and minima of the
  base profile under the bed (end cells of the bed left out) whose
  prominence exceeds the dip's threshold 3 sigma, at cell centres, each
  minimum's ratio to the highest maximum.

Everything is read and checked before anything is drawn: a missing or
malformed input stops with one line on stderr. Exit status
(docs/exit-codes.md): 0 done; 1 usage; 2 bad input (a 1D run, a dataset
or attribute missing or not as expected); 3 the input missing or
unreadable, or an output that cannot be written; 7 a Python package
missing. SIGTERM, SIGHUP and SIGINT end it with 128+N after removing the
temporary being written. Output is deterministic (no dates: the JSON's
"created" is the run's).
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

PROG = "pile2d.py"
USAGE = 1
UNAVAILABLE = 7

# the thesis's second colour scale (Figures 4.13-4.16)
HEAP_SCALE = (0.59, 0.61)
# flank band, as fractions of the pile height; columns next to a wall left out
FLANK_BAND = (0.2, 0.8)
WALL_COLUMNS = 2
MIN_FIT_COLUMNS = 3
DIP_SIGMAS = 3.0
APEX_TIE = 0.01       # of a cell height: columns this close to H are the apex


class ArgParser(argparse.ArgumentParser):
    """argparse with the table's usage status (argparse's own is 2)."""

    def error(self, message):
        self.print_usage(sys.stderr)
        self.exit(USAGE, "%s: %s\n" % (self.prog, message))


def times_arg(s):
    try:
        v = [float(x) for x in s.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError("expected times in s separated by commas, got %r" % s)
    if not v or not all(math.isfinite(x) for x in v):
        raise argparse.ArgumentTypeError("expected finite times in s, got %r" % s)
    return v


def time_arg(s):
    try:
        v = float(s)
    except ValueError:
        raise argparse.ArgumentTypeError("expected a time in s, got %r" % s)
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError("expected a finite time in s, got %r" % s)
    return v


# --- input ------------------------------------------------------------------------

class Run(C.Run2D):
    """The 2D run: grid, times, phi and P [nt][nz][nx], material, provenance."""

    WHAT = "the 2D ekm run to plot"

    def __init__(self, path):
        import numpy as np
        self.path = path
        r = C.rel(path)
        with C._open(path, self.WHAT) as f:
            d = C.read_run2d(f, path, ("phi", "P"),
                             {"x": "m", "z": "m", "t": "s", "phi": "1", "P": "Pa"}, self.WHAT, PROG)
            self.attrs = d["attrs"]
            self.rho_p = C._attr(f, path, "material.rho_p",
                                 "the particle density rho_p, the thesis's rho_b the pressure is scaled with")
            self.phi_co = C._attr(f, path, "material.phi_co",
                                  "the cross-over volume fraction; half of it is the pile's surface")
        if not (self.rho_p > 0 and 0 < self.phi_co < 1):
            raise C.InputError("%s: material.rho_p = %g, material.phi_co = %g: expected rho_p > 0 "
                               "and 0 < phi_co < 1" % (r, self.rho_p, self.phi_co))
        self.x, self.z, self.t = d["x"], d["z"], d["t"]
        nz, nx = self.z.size, self.x.size
        self.phi, self.P = d["phi"], d["P"]
        # cell centres (i + 1/2) dx, (j + 1/2) dz
        self.dx, self.dz = 2 * self.x[0], 2 * self.z[0]
        for n, c, h in (("x", self.x, self.dx), ("z", self.z, self.dz)):
            if not (h > 0 and np.allclose(c, (np.arange(c.size) + 0.5) * h, rtol=1e-9, atol=1e-12 * h)):
                raise C.InputError("%s: dataset /%s: expected the cell centres (i + 1/2) d%s of a "
                                   "uniform grid from 0" % (r, n, n))
        if nx < 2:
            raise C.InputError("%s: dataset /x: one column: %s needs a 2D run ([domain] cells_x > 1)"
                               % (r, PROG))
        self.width, self.height = nx * self.dx, nz * self.dz
        self.phi_s = 0.5 * self.phi_co
        self.inlets = inlet_centres(self.attrs)

    def far(self, i, want):
        """Whether frame i is further from want than half an output interval."""
        import numpy as np
        step = float(np.median(np.diff(self.t))) if self.t.size > 1 else 0.0
        return abs(self.t[i] - want) > 0.5 * step + 1e-9 * max(1.0, abs(want))


def inlet_centres(attrs):
    """The top inlets' centres [m] from the run's top.inlet_x (a number, or
    numbers separated by blanks: docs/scenario-format.md); the top's middle
    for a top.inlet_width without top.inlet_x (its default); [] without a
    segment (the whole top) or a value that is not such a list."""
    v = attrs.get("top.inlet_x")
    if v is None and attrs.get("top.inlet_width") is not None and attrs.get("domain.width") is not None:
        v = 0.5 * float(attrs["domain.width"])
    if v is None:
        return []
    try:
        xs = [float(w) for w in str(v).split()] if isinstance(v, str) else [float(v)]
    except ValueError:
        return []
    return [x for x in xs if math.isfinite(x)]


# --- analysis ---------------------------------------------------------------------

def q(value, units, reason=None, **extra):
    """A number with its units; None (JSON null) with the reason why not."""
    out = {"value": value, "units": units}
    if value is None:
        out["reason"] = reason or "not computed"
    out.update(extra)
    return out


def num(v, digits=7):
    """A finite float for the JSON (None if not finite), to 7 digits."""
    v = float(v)
    return float("%.*g" % (digits, v)) if math.isfinite(v) else None


def surface(phi, z, dz, thr):
    """Per column of one frame phi [nz][nx]: (h [nx] surface height [m],
    nb [nx] number of contiguous bed cells from the bottom)."""
    import numpy as np
    nz, nx = phi.shape
    h, nb = np.zeros(nx), np.zeros(nx, dtype=int)
    for k in range(nx):
        col = phi[:, k]
        n = 0
        while n < nz and col[n] > thr:
            n += 1
        nb[k] = n
        if n == 0:
            continue
        j = n - 1
        if n < nz:
            h[k] = z[j] + (col[j] - thr) / (col[j] - col[j + 1]) * dz
        else:
            h[k] = z[j] + 0.5 * dz
    return h, nb


def fit_flank(x, h, cols, rising):
    """Least-squares line through (x, h) of the columns cols: angle [deg]
    (positive when the surface rises towards the apex), its SE and the
    extent fitted."""
    import numpy as np
    xs, hs = x[cols], h[cols]
    A = np.vstack([xs, np.ones_like(xs)]).T
    (m, b), *_ = np.linalg.lstsq(A, hs, rcond=None)
    res = hs - (m * xs + b)
    sxx = float(np.sum((xs - xs.mean()) ** 2))
    se_m = math.sqrt(float(np.sum(res ** 2)) / (xs.size - 2) / sxx) if xs.size > 2 else float("nan")
    s = m if rising else -m
    return s, b, m, se_m, float(xs.min()), float(xs.max())


def analyse(run, i):
    """The pile's numbers at frame i (see the module comment)."""
    import numpy as np
    phi, P = run.phi[i], run.P[i]
    x, z, dx, dz = run.x, run.z, run.dx, run.dz
    nx = x.size
    out = {"time": q(num(run.t[i]), "s"), "frame": q(i, "1 (index into /t)"),
           "surface_threshold_phi_s": q(num(run.phi_s), "1"), "bed": "none"}
    h, nb = surface(phi, z, dz, run.phi_s)
    out["_h"], out["_nb"] = h, nb          # for the figures (not written)
    base = nb > 0
    keys_m = ("height", "apex_x")
    if not np.any(base):
        why = ("no pile: no cell of the bottom row has phi > phi_s = %.3g (the frame's largest phi "
               "is %.3g)" % (run.phi_s, float(phi.max())))
        for k in keys_m:
            out[k] = q(None, "m", why)
        out["base_extent"] = q(None, "m", why)
        for side in ("left", "right"):
            out["slope_" + side] = {"angle": q(None, "deg", why)}
        out["phi_apex"] = q(None, "1", why)
        out["phi_flank"] = q(None, "1", why)
        out["phi_apex_minus_flank"] = q(None, "1", why)
        out["base_pressure"] = {n: q(None, u, why) for n, u in (
            ("centre", "Pa"), ("max", "Pa"), ("ratio_centre_to_max", "1"), ("max_left", "Pa"),
            ("x_max_left", "m"), ("max_right", "Pa"), ("x_max_right", "m"))}
        out["dip"] = q(None, "1 (true/false)", why)
        out["base_extrema"] = q(None, "Pa", why)
        return out
    H = float(h.max())
    top = np.nonzero(h >= H - APEX_TIE * dz)[0]
    xc = float(x[top].mean())
    dist = np.abs(x - xc)
    apex = np.nonzero(dist <= dist.min() + 1e-9 * dx)[0]     # the centre column(s)
    out["_xc"], out["_centre"] = xc, apex
    out["height"] = q(num(H), "m")
    out["apex_x"] = q(num(xc), "m", top_columns=q(int(top.size), "1"),
                      centre_columns=q(int(apex.size), "1"))
    cols_base = np.nonzero(base)[0]
    out["base_extent"] = q([num(x[cols_base[0]] - 0.5 * dx), num(x[cols_base[-1]] + 0.5 * dx)], "m",
                           touches_walls=bool(base[0] or base[-1]))

    # flanks
    inner = (np.arange(nx) >= WALL_COLUMNS) & (np.arange(nx) < nx - WALL_COLUMNS)
    band = (h >= FLANK_BAND[0] * H) & (h <= FLANK_BAND[1] * H) & inner
    flank_cols = {}
    for side, mask in (("left", x < xc), ("right", x > xc)):
        cols = np.nonzero(band & mask)[0]
        flank_cols[side] = cols
        if cols.size < MIN_FIT_COLUMNS:
            sh = h[mask & inner]
            why = ("%d column(s) on the %s flank with a surface between %g%% and %g%% of the height "
                   "%.3g m (at least %d needed; surface heights there %.3g..%.3g m%s)"
                   % (cols.size, side, 100 * FLANK_BAND[0], 100 * FLANK_BAND[1], H, MIN_FIT_COLUMNS,
                      float(sh.min()) if sh.size else 0.0, float(sh.max()) if sh.size else 0.0,
                      ": a flat layer, not a pile" if sh.size and sh.min() > FLANK_BAND[1] * H else ""))
            out["slope_" + side] = {"angle": q(None, "deg", why)}
            continue
        s, b, m, se_m, lo, hi = fit_flank(x, h, cols, side == "left")
        ang = math.degrees(math.atan(s))
        se = math.degrees(se_m / (1 + s * s)) if math.isfinite(se_m) else float("nan")
        resol = math.degrees(math.atan(abs(s) + dz / (hi - lo)) - math.atan(abs(s)))
        out["slope_" + side] = {
            "angle": q(num(ang), "deg"),
            "se": q(num(se), "deg") if math.isfinite(se) else q(None, "deg", "fewer than 3 columns"),
            "resolution": q(num(resol), "deg"),
            "columns": q(int(cols.size), "1"),
            "x_range": q([num(lo), num(hi)], "m"),
            "_line": (m, b, lo, hi),
        }

    fitted = [sd for sd in ("left", "right") if "_line" in out["slope_" + sd]]
    out["bed"] = "pile" if fitted else "layer"

    # phi under the apex against the flanks, same rows, surface cells left out
    fl = np.concatenate([flank_cols["left"], flank_cols["right"]]).astype(int)
    rows_apex = int(nb[apex].min()) - 1       # rows 0 .. rows_apex-1 are interior in every apex column
    rows, fvals = [], []
    for j in range(max(rows_apex, 0)):
        v = [phi[j, k] for k in fl if j < nb[k] - 1]
        if v:
            rows.append(j)
            fvals += v
    if not rows:
        why = ("no row with interior bed cells both under the apex and in the flank-fit columns (%d "
               "flank columns, %d interior rows under the apex)" % (fl.size, max(rows_apex, 0)))
        out["phi_apex"] = q(None, "1", why)
        out["phi_flank"] = q(None, "1", why)
        out["phi_apex_minus_flank"] = q(None, "1", why)
    else:
        pa = float(phi[np.ix_(rows, apex)].mean())
        pf = float(np.mean(fvals))
        zr = [num(z[rows[0]] - 0.5 * dz), num(z[rows[-1]] + 0.5 * dz)]
        out["phi_apex"] = q(num(pa), "1", cells=q(len(rows) * int(apex.size), "1"), z_range=q(zr, "m"))
        out["phi_flank"] = q(num(pf), "1", cells=q(len(fvals), "1"), z_range=q(zr, "m"))
        out["phi_apex_minus_flank"] = q(num(pa - pf), "1")

    # base pressure
    Pb = P[0]
    bp = {}
    pc = float(Pb[apex].mean())
    bp["centre"] = q(num(pc), "Pa", scaled=q(num(pc / run.rho_p), "Pa/(kg m^-3)"))
    maxima = {}
    for side, mask in (("left", x <= xc), ("right", x >= xc)):
        cols = np.nonzero(mask & base)[0]
        k = int(cols[np.argmax(Pb[cols])])
        maxima[side] = k
        bp["max_" + side] = q(num(Pb[k]), "Pa")
        bp["x_max_" + side] = q(num(x[k]), "m", resolution=q(num(dx), "m"))
    pmax = float(max(Pb[maxima["left"]], Pb[maxima["right"]]))
    bp["max"] = q(num(pmax), "Pa", scaled=q(num(pmax / run.rho_p), "Pa/(kg m^-3)"))
    bp["ratio_centre_to_max"] = (q(num(pc / pmax), "1") if pmax > 0 else
                                 q(None, "1", "P(max) = %.3g Pa is not positive" % pmax))
    out["_maxima"] = maxima
    out["base_pressure"] = bp
    # dip: P(max) - P(centre) against the cell-to-cell noise under the pile
    sigma = base_noise(Pb, base)
    out["base_extrema"] = extrema_json(run, Pb, base, sigma)
    if out["bed"] != "pile":
        out["dip"] = q(None, "1 (true/false)", "no pile (bed: %s): a dip is a pile's; under a flat "
                       "layer one or two cells thick the bottom row's P is its cells' equation of "
                       "state, not the weight above" % out["bed"])
    elif sigma is None:
        out["dip"] = q(None, "1 (true/false)", "the pile's base spans %d cell(s): fewer than 6, no "
                       "estimate of the cell-to-cell noise" % int(base.sum()))
    else:
        thr = max(DIP_SIGMAS * sigma, 1e-9 * abs(pmax))
        depth = pmax - pc
        out["dip"] = q(bool(depth > thr), "1 (true/false)",
                       depth=q(num(depth), "Pa"),
                       relative_depth=(q(num(depth / pmax), "1") if pmax > 0 else
                                       q(None, "1", "P(max) not positive")),
                       noise=q(num(sigma), "Pa"), threshold=q(num(thr), "Pa"))
    return out


def base_noise(Pb, base):
    """The cell-to-cell noise sigma [Pa] of the bottom row's P over its bed
    cells (third differences: the module comment, "dip"); None when fewer
    than 3 third differences lie under the bed."""
    import numpy as np
    nx = Pb.size
    d3 = [Pb[k + 2] - 3 * Pb[k + 1] + 3 * Pb[k] - Pb[k - 1] for k in range(1, nx - 2)
          if base[k - 1:k + 3].all()]
    if len(d3) < 3:
        return None
    return 1.4826 * float(np.median(np.abs(d3))) / math.sqrt(20.0)


def prominent_peaks(y, thr):
    """The interior local maxima k of the profile y (y[k] > y[k-1], y[k] >=
    y[k+1]) whose prominence exceeds thr: y[k] minus the higher of the
    lowest values on either side before a point higher than y[k] (or the
    profile's end). Returns [(k, prominence)]."""
    n = len(y)
    out = []
    for k in range(1, n - 1):
        if not (y[k] > y[k - 1] and y[k] >= y[k + 1]):
            continue
        lo = []
        for step in (-1, 1):
            m, j = y[k], k + step
            while 0 <= j < n and y[j] <= y[k]:
                m = min(m, y[j])
                j += step
            lo.append(m)
        prom = y[k] - max(lo)
        if prom > thr:
            out.append((k, prom))
    return out


def base_extrema(Pb, base, thr):
    """The bottom row's local maxima and minima under the bed (each
    contiguous run of bottom-row bed cells, its end cells left out) that
    stand out by more than thr [Pa]: ([(k, prominence)], [(k, prominence)])."""
    import numpy as np
    maxima, minima = [], []
    cols = np.nonzero(base)[0]
    runs = np.split(cols, np.nonzero(np.diff(cols) > 1)[0] + 1) if cols.size else []
    for r in runs:
        y = [float(v) for v in Pb[r]]
        maxima += [(int(r[k]), p) for k, p in prominent_peaks(y, thr)]
        minima += [(int(r[k]), p) for k, p in prominent_peaks([-v for v in y], thr)]
    return maxima, minima


def extrema_json(run, Pb, base, sigma):
    """base_extrema of the JSON: positions, values and prominences of the
    base profile's maxima and minima (threshold 3 sigma, as the dip's), each
    minimum's ratio to the highest maximum; null with a reason without a
    noise estimate."""
    if sigma is None:
        return q(None, "Pa", "the bed's bottom row spans %d cell(s): fewer than 6, no estimate of "
                 "the cell-to-cell noise" % int(base.sum()))
    thr = max(DIP_SIGMAS * sigma, 1e-9 * float(abs(Pb).max()))
    maxima, minima = base_extrema(Pb, base, thr)
    top = max((float(Pb[k]) for k, _ in maxima), default=None)

    def entry(k, prom, ratio):
        e = {"x": q(num(run.x[k]), "m", resolution=q(num(run.dx), "m")),
             "P": q(num(Pb[k]), "Pa", scaled=q(num(Pb[k] / run.rho_p), "Pa/(kg m^-3)")),
             "prominence": q(num(prom), "Pa")}
        if ratio:
            e["ratio_to_highest_max"] = (q(num(Pb[k] / top), "1") if top and top > 0 else
                                         q(None, "1", "no maximum with a positive P"))
        return e
    return {"maxima": [entry(k, p, False) for k, p in maxima],
            "minima": [entry(k, p, True) for k, p in minima],
            "noise": q(num(sigma), "Pa"), "threshold": q(num(thr), "Pa"),
            "_maxima": [k for k, _ in maxima], "_minima": [k for k, _ in minima]}


def public(res):
    """The analysis without the figures' private entries (keys '_...')."""
    if isinstance(res, dict):
        return {k: public(v) for k, v in res.items() if not k.startswith("_")}
    return res


DEFINITIONS = {
    "scaled_pressure": "P / rho_b with rho_b = material.rho_p (the thesis's rho_b = 1600 kg/m^3, the "
                       "density its material parameters are given per, Section 4.6.2), in Pa/(kg m^-3)",
    "bed_cell": "phi > phi_s = material.phi_co / 2",
    "surface": "h(x): top of the contiguous bed cells from the bottom cell of the column, where phi "
               "crosses phi_s (linear between cell centres); 0 where the bottom cell is not a bed cell",
    "height": "max h(x) over the columns",
    "bed": "none: no bottom-row bed cell; pile: a flank line fitted on at least one side; layer: "
           "a bed but no flank (a flat layer)",
    "apex_x": "the centre: mean x of the top columns, those with h within 1% of a cell of the "
              "height; the centre columns are the one or two columns nearest to it",
    "base_extent": "x from the left face of the leftmost to the right face of the rightmost bottom-row "
                   "bed cell; touches_walls: a bed cell next to a side wall",
    "slope": "least-squares line h(x) through the columns on that side of the apex with h in "
             "[0.2, 0.8] x height, without the two columns next to each side wall, at least 3 "
             "columns; angle = atan(slope), positive rising towards the apex; se from the fit's "
             "residuals; resolution: the angle change a height error of one cell (dz) across the "
             "fitted x_range makes",
    "phi_apex": "mean phi of the centre column(s) over the rows where the flank-fit columns also have "
                "bed cells, each column's topmost (surface) bed cell left out",
    "phi_flank": "mean phi of the flank-fit columns' bed cells over the same rows, surface cells "
                 "left out",
    "base_pressure": "P of the bottom row of cells: centre = mean over the centre column(s); max_left, "
                     "max_right = the largest value under the pile (bottom cell a bed cell) at x <= "
                     "apex_x and at x >= apex_x, at its cell centre; max = the larger",
    "base_extrema": "the local maxima and minima of the bottom row's P under the bed (each contiguous "
                    "run of bottom-row bed cells, its two end cells left out) whose prominence (the "
                    "height above, or depth below, the higher of the lowest (highest) values on either "
                    "side before a higher (lower) point) exceeds threshold = 3 sigma (the dip's noise, "
                    "at least 1e-9 of max |P|), at their cell centres (resolution dx); "
                    "ratio_to_highest_max = P(minimum) / the highest of the maxima; null when the "
                    "bottom row has under 6 bed cells",
    "dip": "max - centre > threshold = 3 sigma (at least 1e-9 max), sigma = 1.4826 "
           "median|P[k+2] - 3P[k+1] + 3P[k] - P[k-1]| / sqrt(20) over the bottom-row bed cells "
           "(the cell-to-cell noise: third differences, blind to a profile quadratic over four "
           "cells); null if the bed is not a pile or the pile's base is under 6 cells",
}


# --- figures ----------------------------------------------------------------------

def _edges(run):
    import numpy as np
    return np.arange(run.x.size + 1) * run.dx, np.arange(run.z.size + 1) * run.dz


def _tlabel(run, i, asked):
    t = run.t[i]
    far = [a for a in asked if run.far(i, a)]
    s = r"$t$ = %g s" % float("%.4g" % t)
    if far:
        s += " (nearest to %s s)" % ", ".join("%g" % a for a in asked)
    return s


def _inch_axes(fig, W, H, left, bottom, w, h):
    """Axes at (left, bottom) of size (w, h) in inches on a W x H figure."""
    return fig.add_axes([left / W, bottom / H, w / W, h / H])


def _colourbar(fig, im, W, H, left, bottom, h, label, extend="neither"):
    cax = _inch_axes(fig, W, H, left, bottom, CB_W, h)
    cb = fig.colorbar(im, cax=cax, extend=extend)
    cb.set_label(label)
    cb.ax.tick_params(direction="out", right=True, left=False, labelsize=6)
    return cb


CB_W, CB_PAD = 0.08, 0.06      # colour bar width and gap to its panel [in]


def phi_figure(run, frames, writer, meta):
    """frames: [(i, [asked times])]; a row of two panels each."""
    import matplotlib.pyplot as plt
    from matplotlib import colors
    xe, ze = _edges(run)
    n = len(frames)
    W = C.PAGE_W
    left, gap, cbl, right = 0.5, 0.08, 0.45, 0.5       # margins, colour bar labels [in]
    pw = (W - left - gap - right - 2 * (CB_PAD + CB_W) - cbl) / 2
    ph = pw * run.height / run.width
    vgap, bottom, top = 0.1, 0.38, 0.06
    H = bottom + n * ph + (n - 1) * vgap + top
    fig = plt.figure(figsize=(W, H))
    cm_full = plt.get_cmap("viridis")
    cm_heap = plt.get_cmap("viridis").copy()
    cm_heap.set_under("0.88")
    cm_heap.set_over("#D55E00")
    for r, (i, asked) in enumerate(frames):
        phi = run.phi[i]
        pmax = float(phi.max())
        y0 = bottom + (n - 1 - r) * (ph + vgap)
        for c in range(2):
            x0 = left + c * (pw + CB_PAD + CB_W + cbl + gap)
            ax = _inch_axes(fig, W, H, x0, y0, pw, ph)
            if c == 0:
                im = ax.pcolormesh(xe, ze, phi, cmap=cm_full, vmin=0.0, vmax=pmax if pmax > 0 else 1.0,
                                   rasterized=True)
                scale = "0 to %.4f" % pmax if pmax > 0 else "0 to 1 (empty)"
                _colourbar(fig, im, W, H, x0 + pw + CB_PAD, y0, ph, r"$\phi$ [-]")
            else:
                im = ax.pcolormesh(xe, ze, phi, cmap=cm_heap, norm=colors.Normalize(*HEAP_SCALE),
                                   rasterized=True)
                scale = "%.2f to %.2f" % HEAP_SCALE
                _colourbar(fig, im, W, H, x0 + pw + CB_PAD, y0, ph, r"$\phi$ [-]", extend="both")
            ax.set_xlim(0, run.width)
            ax.set_ylim(0, run.height)
            ax.text(0.015, 0.955, "(%s) %s\nscale %s" % ("abcdefghijklmnopqrstuvwxyz"[(2 * r + c) % 26],
                                                          _tlabel(run, i, asked), scale),
                    transform=ax.transAxes, ha="left", va="top", fontsize=6.5,
                    bbox=dict(fc="white", ec="none", alpha=0.75, pad=1.0))
            if r == n - 1:
                ax.set_xlabel(r"$x$ [m]")
            else:
                ax.tick_params(labelbottom=False)
            if c == 0:
                ax.set_ylabel(r"$z$ [m]", labelpad=2)
            else:
                ax.tick_params(labelleft=False)
    writer.save(fig, "pile2d_phi", meta)


def pressure_figure(run, i, res, writer, meta, extrema=False):
    import matplotlib.pyplot as plt
    import numpy as np
    xe, ze = _edges(run)
    rb = run.rho_p
    Ps = run.P[i] / rb
    W, left, right = 3.7, 0.58, 0.5
    pw = W - left - right - CB_PAD - CB_W
    ph, bh, vgap, bottom, top = pw * run.height / run.width, 1.45, 0.1, 0.38, 0.06
    H = bottom + bh + vgap + ph + top
    fig = plt.figure(figsize=(W, H))
    ax = _inch_axes(fig, W, H, left, bottom + bh + vgap, pw, ph)
    bx = _inch_axes(fig, W, H, left, bottom, pw, bh)
    vmax = float(Ps.max()) if Ps.max() > 0 else 1.0
    im = ax.pcolormesh(xe, ze, Ps, cmap="magma_r", vmin=min(0.0, float(Ps.min())), vmax=vmax,
                       rasterized=True)
    _colourbar(fig, im, W, H, left + pw + CB_PAD, bottom + bh + vgap, ph,
               r"$P/\rho_b$ [Pa/(kg m$^{-3}$)]")
    ax.set_xlim(0, run.width)
    ax.set_ylim(0, run.height)
    ax.set_ylabel(r"$z$ [m]")
    ax.tick_params(labelbottom=False)
    h = res["_h"]
    if "_xc" in res:
        hx = np.where(res["_nb"] > 0, h, np.nan)
        ax.plot(run.x, hx, color="#56B4E9", lw=0.9, label=r"surface ($\phi = \phi_{co}/2$)")
        for side in ("left", "right"):
            ln = res["slope_" + side].get("_line")
            if ln:
                m, b, lo, hi = ln
                xs = np.array([lo, hi])
                ax.plot(xs, m * xs + b, color="#009E73", lw=1.2, ls="--")
                ang = res["slope_" + side]["angle"]["value"]
                ax.text(xs.mean(), m * xs.mean() + b + 0.06 * run.height, "%.1f\u00b0" % ang,
                        ha="center", va="bottom", fontsize=6.5, color="#009E73")
        ax.legend(loc="upper right", fontsize=6)
    ax.text(0.015, 0.955, "(a) $t$ = %g s" % float("%.4g" % run.t[i]), transform=ax.transAxes,
            ha="left", va="top", fontsize=6.5)
    Pb = run.P[i][0] / rb
    bx.plot(run.x, Pb, color="black", lw=0.9, marker="o", ms=2.2, mfc="white", mew=0.6)
    if extrema and isinstance(res.get("base_extrema"), dict) and "_maxima" in res["base_extrema"]:
        mark_extrema(run, ax, bx, Pb, res["base_extrema"])
    elif "_xc" in res:
        bx.axvline(res["_xc"], color="0.5", lw=0.6, ls=":")
        cen = res["_centre"]
        bx.plot(run.x[cen], Pb[cen], marker="v", color="#0072B2", ms=5, ls="none", label="centre")
        mk = res["_maxima"]
        bx.plot(run.x[[mk["left"], mk["right"]]], Pb[[mk["left"], mk["right"]]], marker="^",
                color="#D55E00", ms=5, ls="none", label="maxima")
        ratio = res["base_pressure"]["ratio_centre_to_max"]["value"]
        dip = res["dip"]["value"]
        txt = r"$P_{\rm centre}/P_{\rm max}$ = %s%s" % (
            "%.3f" % ratio if ratio is not None else "n/a",
            {True: ": dip", False: ": no dip", None: ""}[dip])
        bx.text(0.015, 0.04, txt, transform=bx.transAxes, ha="left", va="bottom", fontsize=6.5)
        bx.legend(loc="upper right", fontsize=6, ncol=2)
    else:
        bx.text(0.5, 0.5, "no pile at this time", transform=bx.transAxes, ha="center", fontsize=7)
    bx.text(0.015, 0.955, "(b) bottom row of cells", transform=bx.transAxes, ha="left", va="top",
            fontsize=6.5)
    bx.set_xlim(0, run.width)
    bx.set_xlabel(r"$x$ [m]")
    bx.set_ylabel(r"$P/\rho_b$ [Pa/(kg m$^{-3}$)]")
    lo = min(0.0, float(Pb.min()) * 1.1)
    hi = float(Pb.max())
    bx.set_ylim(lo, hi * (1.4 if extrema else 1.22) if hi > 0 else 1.0)
    sec = bx.secondary_yaxis("right", functions=(lambda v: v * rb, lambda v: v / rb))
    sec.set_ylabel("$P$ [Pa]")
    sec.tick_params(labelsize=6)
    bx.tick_params(axis="y", right=False)
    writer.save(fig, "pile2d_pressure", meta)


def mark_extrema(run, ax, bx, Pb, ex):
    """--extrema: the inlets' centres (dotted, and a mark on the top of
    panel a) and the base profile's maxima and minima (base_extrema)."""
    for k, xi in enumerate(run.inlets):
        bx.axvline(xi, color="0.5", lw=0.6, ls=":", label="inlets" if k == 0 else None)
        ax.plot([xi], [run.height], marker="v", color="0.3", ms=4, clip_on=False)
    for key, mk, col, lab in (("_maxima", "^", "#D55E00", "maxima"), ("_minima", "v", "#0072B2", "minima")):
        ks = ex[key]
        if ks:
            bx.plot(run.x[ks], Pb[ks], marker=mk, color=col, ms=5, ls="none", label=lab)
    mins = ex["minima"]
    if mins:
        txt = r"$P_{\rm min}/P_{\rm max}$ = " + ", ".join(
            "%.3f" % m["ratio_to_highest_max"]["value"] for m in mins
            if m["ratio_to_highest_max"]["value"] is not None)
        bx.text(0.015, 0.04, txt, transform=bx.transAxes, ha="left", va="bottom", fontsize=6.5)
    bx.legend(loc="upper right", fontsize=6, ncol=3, bbox_to_anchor=(1.0, 0.9))


# --- captions and JSON ------------------------------------------------------------

def provenance_line(prov):
    return "input %s (scenario %s, ekm %s, run created %s)" % (
        prov["file"], prov["scenario"] or "unknown", prov["code_version"] or "unknown",
        prov["created"] or "unknown")


def captions(run, frames, ib, ask_base, prov, extrema=False):
    used = "; ".join("%g s%s" % (run.t[i], " (asked %s)" % ", ".join("%g" % a for a in asked)
                                 if any(run.far(i, a) or a != run.t[i] for a in asked) else "")
                     for i, asked in frames)
    phi = ("pile2d_phi: solid volume fraction phi of the 2D sand pile (thesis Figures 4.13-4.16, "
           "4.19) at the output frames nearest to the times asked: %s. Left: colour scale 0 to the "
           "frame's largest phi; right: %.2f to %.2f (the density variations inside the heap), cells "
           "below %.2f light grey, above %.2f orange. x and z in m, equal aspect. %s."
           % (used, HEAP_SCALE[0], HEAP_SCALE[1], HEAP_SCALE[0], HEAP_SCALE[1], provenance_line(prov)))
    pres = ("pile2d_pressure: (a) pressure P scaled with the bulk density, P/rho_b in Pa/(kg m^-3), "
            "at t = %g s (the frame nearest to %g s; thesis Figure 4.17), with the pile's surface "
            "(phi = phi_co/2 = %.3g, blue) and the least-squares flank lines (green, angles in "
            "degrees). rho_b is the thesis's: the density its material parameters are given per "
            "(rho_b = 1600 kg/m^3, Section 4.6.2), i.e. the run's material.rho_p = %g kg/m^3, not "
            "the local rho_p phi. (b) P/rho_b of the bottom row of cells against x (thesis Figure "
            "4.18; right axis: P in Pa), %s. %s."
            % (run.t[ib], ask_base, run.phi_s, run.rho_p,
               ("the inlets' centres (dotted; marks on the top of (a)) and the profile's local maxima "
                "and minima that stand out by more than 3 sigma of the cell-to-cell noise marked, each "
                "minimum's ratio to the highest maximum given (pile2d.json, base_extrema)") if extrema else
               ("the centre (apex column(s)) and the maxima on either side marked; a dip is P(max) - "
                "P(centre) > 3 sigma of the cell-to-cell noise (pile2d.json, definitions)"),
               provenance_line(prov)))
    return phi, pres


def write_atomic(path, text):
    tmp = os.path.join(os.path.dirname(path) or ".", "." + os.path.basename(path) + ".tmp")
    try:
        with open(tmp, "w") as fh:
            fh.write(text)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def main(argv=None):
    def stop(signum, _frame):
        raise SystemExit(128 + signum)
    for sig in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT):
        signal.signal(sig, stop)
    ap = ArgParser(prog=PROG, description="Figures and numbers of a 2D sand pile run "
                                          "(thesis Section 4.6.3).")
    ap.add_argument("run", help="the 2D ekm output (RUN.h5)")
    ap.add_argument("outdir", help="folder for the figures and pile2d.json")
    ap.add_argument("--times", type=times_arg, default=[0.5, 1.0, 1.5, 2.0, 3.5],
                    help="times [s] of the phi panels, comma-separated (default 0.5,1,1.5,2,3.5)")
    ap.add_argument("--base-time", type=time_arg, default=3.5,
                    help="time [s] of the pressure figure and the first set of numbers (default 3.5)")
    ap.add_argument("--extrema", action="store_true",
                    help="panel (b) of the pressure figure marks the inlets and the base profile's "
                         "local maxima and minima (several sources) instead of the centre and the two "
                         "maxima")
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
        frames = []
        for want in a.times:
            i = run.nearest(want)
            for f in frames:
                if f[0] == i:
                    f[1].append(want)
                    break
            else:
                frames.append((i, [want]))
        ib, il = run.nearest(a.base_time), run.t.size - 1
        res_b, res_l = analyse(run, ib), analyse(run, il)
    except C.InputError as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return e.status
    noted = set()
    for i, asked in frames + [(ib, [a.base_time])]:
        for want in asked:
            if run.far(i, want) and want not in noted:
                noted.add(want)
                print("%s: note: no output near t = %g s (run from %g to %g s): frame t = %g s used"
                      % (PROG, want, run.t[0], run.t[-1], run.t[i]), file=sys.stderr)
    prov = run.provenance()
    cap_phi, cap_p = captions(run, frames, ib, a.base_time, prov, a.extrema)
    subject = provenance_line(prov)
    js = {"program": "figures/pile2d.py", "input": prov, "definitions": DEFINITIONS,
          "material": {"rho_p": q(num(run.rho_p), "kg/m^3"), "phi_co": q(num(run.phi_co), "1")},
          "grid": {"dx": q(num(run.dx), "m"), "dz": q(num(run.dz), "m"),
                   "width": q(num(run.width), "m"), "height": q(num(run.height), "m")},
          "base_time": dict(asked=q(num(a.base_time), "s"), **public(res_b)),
          "last_frame": public(res_l)}
    try:
        text = json.dumps(js, indent=1, allow_nan=False) + "\n"
    except ValueError as e:      # a NaN slipped through: a bug, not an input problem
        print("%s: internal error: %s" % (PROG, e), file=sys.stderr)
        return 5
    C.style()
    w = C.Writer(a.outdir)
    try:
        os.makedirs(a.outdir, exist_ok=True)
        phi_figure(run, frames, w, {"Title": "Sand pile: solid volume fraction (pile2d.py)",
                                    "Subject": subject, "Keywords": cap_phi})
        pressure_figure(run, ib, res_b, w, {"Title": "Sand pile: pressure (pile2d.py)",
                                            "Subject": subject, "Keywords": cap_p}, a.extrema)
        write_atomic(os.path.join(a.outdir, "pile2d_captions.txt"), cap_phi + "\n\n" + cap_p + "\n")
        write_atomic(os.path.join(a.outdir, "pile2d.json"), text)
    except OSError as e:
        print("%s: %s: cannot write (%s)" % (PROG, C.rel(e.filename or a.outdir), e.strerror or e),
              file=sys.stderr)
        return C.IO_ERROR
    print("%s: %s: pile2d_phi, pile2d_pressure (.pdf, .png), pile2d_captions.txt, pile2d.json"
          % (PROG, a.outdir))
    return 0


if __name__ == "__main__":
    sys.exit(main())
