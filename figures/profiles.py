"""profiles.py: figure 1, EKM profiles over DEM profiles (+-2 SE bands).

Every parameter set's EKM run of a point is drawn: ekm.h5 (thesis, solid)
and each ekm_<set>.h5 there (the run with RES/calibration/<set>/fit.ini;
dash-dotted or dotted), the legend naming the set.

Steady scenarios (scored with ekm_time = last: the score's options): the DEM's time-averaged
profile against the EKM's last output. Time series (filling): one row per
chosen DEM window, the EKM interpolated linearly in time to the window's
mid-time (as `ekmcompare score` does). Fields: the scenario's scored fields
([compare] fields) in the order phi, velocity, T, P, sxz, szz. z is shown
as z/d, d the DEM's mean grain diameter; the DEM z = 0 is the base, as the
EKM's (shift of the score's options added). Field axes are scaled to the profiles
themselves: an SE band much wider than that runs off the axis.
"""
import math
import re

import numpy as np

import common as C

# a few sweep points read well as colours in one figure; more get a figure each
MAX_POINTS_AS_COLOURS = 3
# the plotted z range ends 2 d above the highest bin with this much material
PHI_RANGE = 1e-2
LETTERS = "abcdefghijklmnopqrstuvwxyz"


def dem_profile(cg, name, it=None):
    """(value, se) at window `it`; the time average over the windows when
    it is None (steady: there is one)."""
    v, s = cg.val[name], cg.se[name]
    if it is not None:
        return v[it], s[it]
    if v.shape[0] == 1:
        return v[0], s[0]
    n = v.shape[0]
    return np.nanmean(v, axis=0), np.sqrt(np.nansum(s ** 2, axis=0)) / n


def masked(name, val, phi):
    """Velocity and temperature are not drawn where there is no material."""
    if name in ("vx", "vz", "T") and phi is not None:
        val = np.where(phi > C.PHI_VISIBLE, val, np.nan)
    return val


def set_line(mode, index, colour):
    """Line style of the EKM run with the index-th parameter set (0:
    thesis, ekm.h5, as style(.., "ekm", ..)); the others dash-dotted or
    dotted in their own colour (one point) or the point's colour."""
    if index == 0:
        return style(mode, "ekm", colour)
    set_colour, dash = C.set_style(index)
    return dict(color=set_colour if mode == "single" else colour, ls=dash, lw=1.2)


def style(mode, src, colour):
    """Line style of a source: one point: colour by source; several points:
    colour by point, dash by source."""
    if mode == "single":
        return {
            "liggghts": dict(color=C.ENGINE_COLOUR["liggghts"], ls="-", lw=0.9),
            "lammps": dict(color=C.ENGINE_COLOUR["lammps"], ls="--", lw=0.9),
            "ekm": dict(color=C.EKM_COLOUR, ls="-", lw=1.3),
        }[src]
    return {
        "liggghts": dict(color=colour, ls="--", lw=0.9),
        "lammps": dict(color=colour, ls=":", lw=1.1),
        "ekm": dict(color=colour, ls="-", lw=1.3),
    }[src]


class Extent:
    """The x range of a panel (or column): the lines, and the bands."""

    def __init__(self):
        self.lines, self.bands = [], []

    def add(self, line, lo=None, hi=None):
        self.lines.append(np.ravel(line))
        if lo is not None:
            self.bands += [np.ravel(lo), np.ravel(hi)]

    def limits(self, name):
        a = np.concatenate(self.lines) if self.lines else np.array([])
        a = a[np.isfinite(a)]
        if a.size == 0:
            return None
        lo, hi = a.min(), a.max()
        span = hi - lo if hi > lo else max(abs(hi), 1e-30)
        if self.bands:
            b = np.concatenate(self.bands)
            b = b[np.isfinite(b)]
            if b.size:
                # bands are shown up to a quarter of the lines' span beyond them
                lo = max(min(lo, b.min()), lo - 0.25 * span)
                hi = min(max(hi, b.max()), hi + 0.25 * span)
        pad = 0.04 * (hi - lo if hi > lo else span)
        lo, hi = lo - pad, hi + pad
        if name == "phi" and a.min() < 0.25 * a.max():
            lo = 0.0       # the profile reaches the dilute edge: phi from 0
        return lo, hi

    def scale(self, name):
        return 0 if name == "phi" or not self.lines else C.scale_exponent(np.concatenate(self.lines))


def draw_point(ax, name, pt, d, mode, colour, ext, set_index, its=None, t=None):
    """One field of one point: each DEM engine (window its[engine], or the
    time average) with its +-2 SE band, then the EKM (at time t, or its last
    output) of the thesis set and of every other parameter set run there
    (set_index: set name -> its index in the sets' order)."""
    for e, cg in pt.cg.items():
        it = None if its is None else its[e]
        v, s = dem_profile(cg, name, it)
        phi = dem_profile(cg, "phi", it)[0] if "phi" in cg.val else None
        v = masked(name, v, phi)
        zz = (cg.z + cg.shift) / d
        st = style(mode, e, colour)
        ok = np.isfinite(v) & np.isfinite(s)
        lo, hi = np.where(ok, v - 2 * s, np.nan), np.where(ok, v + 2 * s, np.nan)
        ax.fill_betweenx(zz, lo, hi, color=st["color"], alpha=0.18 if mode == "single" else 0.13, lw=0)
        ax.plot(v, zz, **st)
        ext.add(v, lo, hi)
    for k, e in [(0, pt.ekm)] + [(set_index[n], r) for n, r in pt.ekm_sets.items()]:
        v = e.val[name][-1] if t is None else e.at(name, t)
        phi = None
        if "phi" in e.val:
            phi = e.val["phi"][-1] if t is None else e.at("phi", t)
        v = masked(name, v, phi)
        ax.plot(v, (e.z if t is None else e.z_at(t)) / d, **set_line(mode, k, colour))
        ext.add(v)


def z_range(points, d):
    """z limits [m]: from the base (or the lowest DEM bin with material, if
    lower) to 2 d above the highest material, within the domains."""
    lo, hi, top = 0.0, 0.0, 0.0
    for pt in points:
        for cg in pt.cg.values():
            z = cg.z + cg.shift
            top = max(top, z[-1])
            if "phi" not in cg.val:
                continue
            idx = np.nonzero((np.nan_to_num(cg.val["phi"]) > PHI_RANGE).any(axis=0))[0]
            if idx.size:
                lo, hi = min(lo, z[idx[0]]), max(hi, z[idx[-1]])
        e = pt.ekm
        top = max(top, e.top)
        if "phi" in e.val:
            idx = np.nonzero((e.val["phi"] > PHI_RANGE).any(axis=0))[0]
            if idx.size:
                hi = max(hi, e.z[idx[-1]])
        else:
            hi = max(hi, e.top)
    if hi <= 0:
        hi = top
    return lo - 0.25 * d, min(hi + 2 * d, top)


def finish_panel(ax, name, units, ext, exp, zlim, d, letter, xlabel=True):
    import matplotlib.ticker as mt
    lim = ext.limits(name)
    if lim is not None:
        ax.set_xlim(*lim)
    if exp:
        f = 10.0 ** exp
        ax.xaxis.set_major_formatter(mt.FuncFormatter(lambda x, _p, f=f: "%g" % round(x / f, 6)))
    ax.xaxis.set_major_locator(mt.MaxNLocator(4))
    if xlabel:
        ax.set_xlabel(C.field_axis_label(name, units, exp))
    ax.set_ylim(zlim[0] / d, zlim[1] / d)
    if zlim[0] < 0:
        ax.axhline(0.0, color="0.6", lw=0.5, zorder=0)
    ax.text(0.0, 1.02, "(%s)" % letter, transform=ax.transAxes, ha="left", va="bottom",
            fontsize=8, fontweight="bold")


def point_label(pt):
    """'theta22' -> 'theta = 22 deg', 'phi0.50-rate5' -> 'phi = 0.50, rate 5/s'."""
    m = re.fullmatch(r"theta([0-9.]+)", pt.name)
    if m:
        return r"$\theta$ = %s$\degree$" % m.group(1)
    m = re.fullmatch(r"phi([0-9.]+)-rate([0-9.]+)", pt.name)
    if m:
        return r"$\phi$ = %s, $\dot\gamma$ = %s s$^{-1}$" % m.groups()
    return pt.name or "-"


def legend_handles(points, mode, colours, set_index):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    h = []
    engines = [e for e in C.ENGINES if any(e in p.cg for p in points)]
    ref = None if mode == "single" else "0.2"
    for e in engines:
        h.append((Line2D([], [], **style(mode, e, ref)), r"%s ($\pm$2 SE)" % C.ENGINE_LABEL[e]))
    sets = sorted({n for p in points for n in p.ekm_sets}, key=lambda n: set_index[n])
    h.append((Line2D([], [], **style(mode, "ekm", ref)), C.EKM_LABEL + (", %s" % C.THESIS if sets else "")))
    for n in sets:
        h.append((Line2D([], [], **set_line(mode, set_index[n], ref)), "%s, %s" % (C.EKM_LABEL, n)))
    if mode != "single":
        for p, c in zip(points, colours):
            h.append((Patch(color=c, lw=0), point_label(p)))
    return h


def zlabel(d):
    return r"$z/d$  ($d$ = %.2f mm)" % (d * 1e3)


def mean_d(points):
    return float(np.mean([c.d for p in points for c in p.cg.values()]))


def steady_figure(sc, points, writer, stem, set_index):
    """Steady profiles of one or a few points of a scenario: one panel per
    field, three to a row; the legend in a spare panel or above."""
    import matplotlib.pyplot as plt
    fields = sc.plotted_fields()
    n = len(fields)
    ncols = 3 if n > 3 else n
    nrows = int(math.ceil(n / ncols))
    spare = nrows * ncols - n
    mode = "single" if len(points) == 1 else "points"
    handles = legend_handles(points, mode, C.POINT_COLOURS, set_index)
    top_h = 0.0 if spare else 0.25 * int(math.ceil(len(handles) / 4))
    fig, axes = plt.subplots(nrows, ncols, figsize=(C.PAGE_W, 2.05 * nrows + top_h),
                             sharey=True, squeeze=False)
    flat = list(axes.ravel())
    d = mean_d(points)
    zlim = z_range(points, d)
    for k, (ax, name) in enumerate(zip(flat, fields)):
        ext = Extent()
        for pt, col in zip(points, C.POINT_COLOURS):
            draw_point(ax, name, pt, d, mode, col, ext, set_index)
        finish_panel(ax, name, sc.units[name], ext, ext.scale(name), zlim, d, LETTERS[k])
    for r in range(nrows):
        axes[r, 0].set_ylabel(zlabel(d))
    hs, ls = [a for a, _ in handles], [b for _, b in handles]
    # a figure of one sweep point names it in the legend's title
    title = point_label(points[0]) if len(points) == 1 and points[0].name else None
    for ax in flat[n:]:
        ax.axis("off")
    if spare:
        flat[n].legend(hs, ls, loc="center left", handlelength=2.6, title=title,
                       title_fontsize=7)
        fig.tight_layout(h_pad=0.6, w_pad=0.6)
    else:
        if title:
            hs, ls = hs + [plt.Line2D([], [], ls="none")], ls + [title]
        fig.legend(hs, ls, loc="upper center", ncol=min(len(hs), 4), handlelength=2.6,
                   bbox_to_anchor=(0.5, 1.0))
        fig.tight_layout(rect=(0, 0, 1, 1 - top_h / fig.get_figheight()), h_pad=0.6, w_pad=0.6)
    writer.save(fig, stem)


def series_times(cg, nrows=3):
    """DEM windows shown for a time series: nearest to 0.3, 0.65 and 1 of
    the last window's time (filling: during the inflow, just after it
    stopped, at rest), distinct."""
    out = []
    for frac in (np.linspace(0.3, 1.0, nrows) if nrows > 1 else [1.0]):
        i = int(np.argmin(np.abs(cg.t - frac * cg.t[-1])))
        if i not in out:
            out.append(i)
    return out


def series_figure(sc, pt, writer, stem, set_index):
    """Time series (filling): rows = DEM windows, columns = fields."""
    import matplotlib.pyplot as plt
    fields = sc.plotted_fields()
    n = len(fields)
    first = next(iter(pt.cg.values()))
    rows = series_times(first)
    nrows = len(rows)
    top_h = 0.3
    fig, axes = plt.subplots(nrows, n, figsize=(C.PAGE_W, 1.8 * nrows + top_h), sharey=True,
                             sharex="col", squeeze=False)
    d = mean_d([pt])
    zlim = z_range([pt], d)
    exts = [Extent() for _ in fields]
    for r, it in enumerate(rows):
        t = float(first.t[it])
        its = {e: int(np.argmin(np.abs(cg.t - t))) for e, cg in pt.cg.items()}
        for c, name in enumerate(fields):
            draw_point(axes[r, c], name, pt, d, "single", None, exts[c], set_index, its=its, t=t)
        axes[r, 0].set_ylabel(zlabel(d))
        axes[r, 0].text(1.0, 1.02, r"$t$ = %.2f s" % t, transform=axes[r, 0].transAxes,
                        ha="right", va="bottom", fontsize=7)
    for c, name in enumerate(fields):
        exp = exts[c].scale(name)
        for r in range(nrows):
            finish_panel(axes[r, c], name, sc.units[name], exts[c], exp, zlim, d, LETTERS[r * n + c],
                         xlabel=(r == nrows - 1))
    h = legend_handles([pt], "single", None, set_index)
    fig.legend([a for a, _ in h], [b for _, b in h], loc="upper center", ncol=len(h),
               handlelength=2.6, bbox_to_anchor=(0.5, 1.0))
    fig.tight_layout(rect=(0, 0, 1, 1 - top_h / fig.get_figheight()), h_pad=0.5, w_pad=0.5)
    writer.save(fig, stem)


def make(scenarios, writer, set_names):
    """set_names: the parameter sets in their order (thesis first); a run
    ekm_<set>.h5 of a set not among them comes after them."""
    set_index = {n: i for i, n in enumerate(set_names)}
    for n in sorted({n for sc in scenarios for p in sc.points for n in p.ekm_sets}):
        set_index.setdefault(n, len(set_index))
    for sc in scenarios:
        if sc.twod:
            continue   # maps, not profiles: figures/pilemaps.py
        pts = [p for p in sc.points if p.cg and p.ekm is not None]
        if not pts:
            continue
        stem = "profiles_%s" % sc.name
        if not sc.steady:
            for p in pts:
                series_figure(sc, p, writer, stem + ("_%s" % p.name if p.name else ""), set_index)
        elif 1 < len(pts) <= MAX_POINTS_AS_COLOURS:
            steady_figure(sc, pts, writer, stem, set_index)
        else:
            for p in pts:
                steady_figure(sc, [p], writer, stem + ("_%s" % p.name if p.name else ""), set_index)
