"""rheology.py: the simple-shear rheology figures.

rheology_simple_shear: P and |sxz|/P against the shear rate at each phi of
the volume-controlled sweep: DEM (LAMMPS; Lees-Edwards) points with error
bars, the EKM runs at the same points and, as lines, the EKM's closed form
for steady homogeneous simple shear of the thesis set.

rheology_fit: the rheology the calibration fits, every parameter set
against the DEM points of both simple-shear sweeps (fixed volume: squares;
fixed normal stress: circles), +-2 SE: (a) mu = |sxz|/P and (b) phi against
the inertial number I = gdot d / sqrt(P / rho_p), (c) P / (rho_p d^2
gdot^2) and (d) T / (d gdot)^2 against phi; the EKM lines at each of the
sweeps' shear rates (they coincide where the closed form does not depend
on the rate, phi < phi_co); below them (e-h) the residuals (model - DEM)/SE
of each point for each set: the model at the point's phi and rate for mu,
P and T (as `ekmcompare fit --rheology` takes them), and for phi the
model's phi at the point's I and rate.

The closed form is never written out here: it is libekm's ekm_homog_shear,
through `ekm homog` (docs/model/law.md) with scenarios/simple_shear.ini's
[material] (thesis) or RES/calibration/<set>/fit.ini (a fitted set). rho_p
scaling the DEM pressure is the thesis set's (the grains'); d is the CG's
mean grain diameter.

A point's phi and shear rate are its sweep variables phi and rate in the
score table (each row's `vars`: the resolved scenario's points[].vars); the
DEM phi of rheology_fit is the measured one (the pressure sweep's phi is
the response). DEM values are the spatial means of the steady profiles
(the flow is homogeneous); their SE is the mean of the profile's SEs, which
assumes the bins fully correlated (an upper bound; the fit's convention).
The EKM run value is the mean over the cells of its last output. In
rheology_simple_shear the DEM markers are drawn 5% left of their shear
rate so as not to hide the EKM's.
"""

import os
import re

import numpy as np

import common as C

SCENARIO = "simple_shear"
SCENARIO_P = "simple_shear_p"
SWEEPS = ((SCENARIO, "fixed volume", "s"), (SCENARIO_P, "fixed normal stress", "o"))
# the phi grid of the closed-form lines (points at phi >= phi_cp have no
# steady state and are not drawn)
PHI_GRID = (0.30, 0.70, 1201)
RATE_LINE_POINTS = 60
# residuals beyond +-RES_CLIP SE are drawn at the edge (and counted in a note)
RES_CLIP = 50.0


def point_rate(pt):
    """Shear rate [1/s] of a point: its sweep variable rate, else its tag
    (...-rate<R>), else (a single case) its EKM run's walls."""
    if "rate" in pt.vars:
        try:
            return float(pt.vars["rate"])
        except ValueError:
            raise C.InputError("%s: vars.rate: expected a number, got %r" % (pt.where, pt.vars["rate"]))
    m = re.fullmatch(r"(phi|p)([0-9.eE+-]+)-rate([0-9.eE+-]+)", pt.name)
    if m:
        return float(m.group(3))
    e = pt.ekm
    why = "the shear rate of the single simple-shear case"
    if "top.shear_rate" in e.attrs:  # a pressure-held wall moved at an imposed rate
        return e.number("top.shear_rate", why)
    return abs(e.number("top.velocity", why) - e.number("bottom.velocity", why)) / e.number("domain.length", why)


def point_state(pt):
    """(phi, shear rate [1/s]) of a point: its sweep variables phi and rate
    in the score table (the resolved scenario's points[].vars)."""
    out = []
    for name in ("phi", "rate"):
        if name not in pt.vars:
            raise C.InputError("%s: vars.%s: missing (the point's %s, from the resolved scenario)"
                               % (pt.where, name, name))
        try:
            out.append(float(pt.vars[name]))
        except ValueError:
            raise C.InputError("%s: vars.%s: expected a number, got %r" % (pt.where, name, pt.vars[name]))
    return tuple(out)


def dem_mean(cg, name):
    v, s = cg.val[name], cg.se[name]
    v = np.nanmean(v, axis=0) if v.shape[0] > 1 else v[0]
    s = np.sqrt(np.nanmean(s ** 2, axis=0) / s.shape[0]) if s.shape[0] > 1 else s[0]
    ok = np.isfinite(v)
    return float(np.mean(v[ok])), float(np.mean(s[np.isfinite(s)])) if np.isfinite(s).any() else np.nan


def scenario_ini(repo):
    ini = os.path.join(repo, "scenarios", SCENARIO + ".ini")
    if not os.path.isfile(ini):
        raise C.missing(ini, "the thesis parameter set: the [material] of the simple-shear scenario")
    return ini


def homog_points(js, what):
    """{(phi, rate): point} of ekm homog's output; state None without one."""
    out = {}
    for p in js["points"]:
        try:
            key = (float(p["phi"]), float(p["rate"]))
            out[key] = p if p["status"] == "ok" else None
        except (KeyError, TypeError, ValueError):
            raise C.InputError("%s: ekm homog: a point without phi, rate and status" % what)
    return out


# --- data -----------------------------------------------------------------------

class DemPoint:
    """A DEM simple-shear point: spatial means and SEs, the rate and d."""

    def __init__(self, sweep, pt, cg, rate):
        self.sweep, self.name, self.rate, self.d = sweep, pt.name, rate, cg.d
        for n in ("phi", "P", "sxz", "T"):
            v, s = dem_mean(cg, n) if n in cg.val else (np.nan, np.nan)
            setattr(self, n, abs(v) if n == "sxz" else v)
            setattr(self, n + "_se", s)
        S, P = self.sxz, self.P
        self.mu = S / P if P > 0 else np.nan
        self.mu_se = self.mu * np.sqrt((self.sxz_se / S) ** 2 + (self.P_se / P) ** 2) if S > 0 and P > 0 else np.nan


class SetModel:
    """One parameter set's closed form: the phi grid at the sweeps' rates
    and its state at each DEM point's (phi, rate)."""

    def __init__(self, pset, index, grid, at_points):
        self.pset, self.index = pset, index
        self.material = grid["material"]
        self.grid = grid                     # ekm homog output on PHI_GRID x rates
        self.at = at_points                  # [DemPoint index] -> point dict or None


class FitData:
    def __init__(self):
        self.dem = []          # DemPoint, both sweeps
        self.sweeps = []       # (label, marker) present
        self.models = []       # SetModel per parameter set
        self.rates = []        # the sweeps' rates [1/s]
        self.rho_p = None      # the thesis set's rho_p [kg/m^3]
        self.notes = []


def prepare(scenarios, ekm, repo, sets):
    """Everything the rheology figures need, read and computed before any
    drawing: the DEM points and `ekm homog` of every set. Returns
    {"rate": (rows, lines) or None, "fit": FitData or None, "notes": [..]}."""
    out = {"rate": None, "fit": None, "notes": []}
    by = {s.name: s for s in scenarios}
    need_fit = []
    for name, label, mk in SWEEPS:
        sc = by.get(name)
        if sc is None:
            continue
        if not all(f in sc.fields for f in ("phi", "P", "sxz")):
            out["notes"].append("%s: phi, P and sxz are not all scored: left out of rheology_fit" % name)
            continue
        pts = [p for p in sc.points if p.ekm is not None and p.cg]
        if pts:
            need_fit.append((label, mk, pts))
    sc = by.get(SCENARIO)
    if sc is not None and not ("P" in sc.fields and "sxz" in sc.fields):
        out["notes"].append("%s: P and sxz are not scored: no rheology figure" % SCENARIO)
        sc = None
    rows = collect(sc) if sc is not None else []
    if sc is not None and not rows:
        out["notes"].append("%s: no EKM run: no rheology figure" % SCENARIO)
    if not rows and not need_fit:
        return out
    ini = scenario_ini(repo)
    if rows:
        phis = sorted({r[0] for r in rows})
        rates = sorted({r[1] for r in rows})
        gd = np.geomspace(min(rates) / 1.5, max(rates) * 1.5, RATE_LINE_POINTS)
        lines = {}
        for p in phis:
            js = C.homog(ekm, ini, sets[0], (p, p, 1), gd)
            pts = homog_points(js, "phi %g" % p)
            lines[p] = [(g, pts.get((p, float(g)))) for g in gd]
        out["rate"] = (rows, lines, gd)
    if need_fit:
        out["fit"] = fit_data(need_fit, ekm, ini, sets)
        out["notes"] += out["fit"].notes
    return out


def fit_data(sweeps, ekm, ini, sets):
    fd = FitData()
    for label, mk, pts in sweeps:
        n0 = len(fd.dem)
        for pt in pts:
            rate = point_rate(pt)
            for e, cg in pt.cg.items():
                dp = DemPoint(label, pt, cg, rate)
                if np.isfinite(dp.phi) and dp.P > 0:
                    fd.dem.append(dp)
        if len(fd.dem) > n0:
            fd.sweeps.append((label, mk))
    fd.rates = sorted({p.rate for p in fd.dem})
    for i, ps in enumerate(sets):
        grid = C.homog(ekm, ini, ps, PHI_GRID, fd.rates)
        at = []
        for p in fd.dem:
            if not 0 < p.phi < 1:
                at.append(None)
                continue
            js = C.homog(ekm, ini, ps, (p.phi, p.phi, 1), [p.rate])
            at.append(js["points"][0] if js["points"][0].get("status") == "ok" else None)
        miss = sum(a is None for a in at)
        if miss:
            fd.notes.append("parameter set %s: no steady homogeneous shear at %d DEM point(s) "
                            "(phi >= its phi_cp): no residual there" % (ps.name, miss))
        fd.models.append(SetModel(ps, i, grid, at))
        if i == 0:
            fd.rho_p = float(grid["material"]["rho_p"])
    return fd


def collect(sc):
    """Rows (phi, rate, source, P, P_se, mu, mu_se) of the volume sweep."""
    rows = []
    for pt in sc.points:
        if pt.ekm is None:
            continue
        phi, rate = point_state(pt)
        for e, cg in pt.cg.items():
            P, Pse = dem_mean(cg, "P")
            S, Sse = dem_mean(cg, "sxz")
            S = abs(S)
            mu = S / P
            mu_se = mu * np.sqrt((Sse / S) ** 2 + (Pse / P) ** 2) if S > 0 and P > 0 else np.nan
            rows.append((phi, rate, e, P, Pse, mu, mu_se))
        P = float(np.mean(pt.ekm.val["P"][-1]))
        S = abs(float(np.mean(pt.ekm.val["sxz"][-1])))
        rows.append((phi, rate, "ekm", P, np.nan, S / P if P > 0 else np.nan, np.nan))
    return rows


# --- drawing ---------------------------------------------------------------------

def make(prepared, writer):
    notes = list(prepared["notes"])
    if prepared["rate"] is not None:
        notes += make_phi_rate(prepared["rate"], writer)
    if prepared["fit"] is not None:
        notes += make_fit(prepared["fit"], writer)
    return notes


def num(v):
    """A number of ekm homog's output; NaN for null (a closure without a
    temperature prints T as null)."""
    return np.nan if v is None else float(v)


def phi_limit(material):
    """The volume fraction where a set's closure ends: the EKM's phi_cp,
    ekm_jam's phi_J, mu_i's phi_max (docs/model/closures.md)."""
    for k in ("phi_cp", "phi_J", "phi_max"):
        if k in material:
            return float(material[k])
    raise C.InputError("ekm homog: material without phi_cp, phi_J or phi_max")


def model_label(pset):
    """The legend's name of a set's model: the EKM, or its closure style."""
    return "%s, %s" % ("EKM" if pset.closure in (None, "ekm_full", "ekm_thesis") else pset.closure, pset.name)


def model_curves(m, rate, d, rho_fallback):
    """Arrays phi, I, mu, P*, T* of a set's grid at one rate (ok points)."""
    rho = float(m.material["rho_p"]) or rho_fallback
    ph, P, T, mu = [], [], [], []
    for p in m.grid["points"]:
        if p.get("status") != "ok" or float(p["rate"]) != rate:
            continue
        ph.append(float(p["phi"]))
        P.append(float(p["P"]))
        T.append(num(p["T"]))
        mu.append(float(p["mu"]))
    ph, P, T, mu = map(np.asarray, (ph, P, T, mu))
    return dict(phi=ph, I=rate * d / np.sqrt(P / rho), mu=mu, Ps=P / (rho * d ** 2 * rate ** 2),
                Ts=T / (d * rate) ** 2)


def make_fit(fd, writer):
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    notes = []
    d = float(np.mean([p.d for p in fd.dem]))
    rho = fd.rho_p
    fig, axes = plt.subplots(2, 4, figsize=(C.PAGE_W, 4.4), sharex="col",
                             gridspec_kw=dict(height_ratios=(1.6, 1.0)))
    top, bot = axes[0], axes[1]
    marker = dict(fd.sweeps)
    # the EKM lines: every set at every rate of the sweeps
    for m in fd.models:
        colour, dash = C.set_style(m.index)
        for r in fd.rates:
            c = model_curves(m, r, d, rho)
            if c["phi"].size == 0:
                continue
            kw = dict(color=colour, ls=dash, lw=0.8, zorder=1)
            top[0].plot(c["I"], c["mu"], **kw)
            top[1].plot(c["I"], c["phi"], **kw)
            top[2].plot(c["phi"], c["Ps"], **kw)
            top[3].plot(c["phi"], c["Ts"], **kw)
    # the DEM points, +-2 SE
    xs = {k: [] for k in ("I", "phi")}
    for p in fd.dem:
        I = p.rate * p.d / np.sqrt(p.P / rho)
        sP = rho * p.d ** 2 * p.rate ** 2
        sT = (p.d * p.rate) ** 2
        kw = dict(color="0.15", marker=marker[p.sweep], ls="none", ms=3.5, mfc="white", mew=0.8, zorder=3)

        def bar(se, scale=1.0):
            return [2 * se / scale] if np.isfinite(se) else None
        top[0].errorbar([I], [p.mu], yerr=bar(p.mu_se), **kw)
        top[1].errorbar([I], [p.phi], yerr=bar(p.phi_se), **kw)
        top[2].errorbar([p.phi], [p.P / sP], yerr=bar(p.P_se, sP), **kw)
        if np.isfinite(p.T):
            top[3].errorbar([p.phi], [p.T / sT], yerr=bar(p.T_se, sT), **kw)
        xs["I"].append(I)
        xs["phi"].append(p.phi)
    # residuals (model - DEM)/SE, per point and set
    offsets = np.linspace(-0.15, 0.15, len(fd.models)) if len(fd.models) > 1 else [0.0]
    big = 0
    for m, off in zip(fd.models, offsets):
        colour, _dash = C.set_style(m.index)
        for k, p, r in residuals(fd, m):
            if not np.isfinite(r):
                continue
            x = p.rate * p.d / np.sqrt(p.P / rho) * 10 ** (off * 0.1) if k < 2 else p.phi + off * 0.01
            big += abs(r) > RES_CLIP
            bot[k].plot([x], [np.clip(r, -RES_CLIP, RES_CLIP)], color=colour, marker=marker[p.sweep], ls="none",
                        ms=3.2, mew=0.7, mfc=colour if m.index == 0 else "white", zorder=2)
    if big:
        notes.append("rheology_fit: %d residual(s) beyond +-%g SE drawn at +-%g" % (big, RES_CLIP, RES_CLIP))
    # axes
    for k in (0, 1):
        top[k].set_xscale("log")
        lo, hi = min(xs["I"]) / 2.0, max(xs["I"]) * 2.0
        top[k].set_xlim(lo, hi)
        bot[k].set_xlabel(r"$I = \dot\gamma d / \sqrt{P/\rho_p}$")
    plo, phi_hi = min(xs["phi"]) - 0.03, max(max(xs["phi"]), max(phi_limit(m.material) for m in fd.models))
    for k in (2, 3):
        top[k].set_xlim(plo, phi_hi + 0.01)
        top[k].set_yscale("log")
        bot[k].set_xlabel(r"volume fraction $\phi$")
    top[1].set_ylim(plo, phi_hi + 0.01)
    top[0].set_ylabel(r"$\mu = |\sigma_{xz}|/P$")
    top[1].set_ylabel(r"$\phi$")
    top[2].set_ylabel(r"$P / (\rho_p d^2 \dot\gamma^2)$")
    top[3].set_ylabel(r"$T / (d \dot\gamma)^2$")
    dem_y = {0: [p.mu for p in fd.dem], 2: [p.P / (rho * p.d ** 2 * p.rate ** 2) for p in fd.dem],
             3: [p.T / (p.d * p.rate) ** 2 for p in fd.dem if np.isfinite(p.T)]}
    for k, ys in dem_y.items():
        ys = [y for y in ys if np.isfinite(y) and y > 0]
        if not ys:
            continue
        if k == 0:
            top[0].set_ylim(0, 1.6 * max(ys))
        else:
            top[k].set_ylim(min(ys) / 10, max(ys) * 10)
    import matplotlib.ticker as mt
    for ax in bot:
        ax.axhline(0.0, color="0.5", lw=0.5, zorder=0)
        for y in (-2, 2):
            ax.axhline(y, color="0.5", lw=0.4, ls=":", zorder=0)
        # linear within +-2 SE, logarithmic beyond, up to the +-50 drawn
        ax.set_yscale("symlog", linthresh=2.0, linscale=0.8)
        ax.set_ylim(-RES_CLIP * 1.4, RES_CLIP * 1.4)
        ax.yaxis.set_major_locator(mt.FixedLocator([-RES_CLIP, -10, -2, 0, 2, 10, RES_CLIP]))
        ax.yaxis.set_major_formatter(mt.FuncFormatter(lambda y, _p: "%g" % y))
        ax.yaxis.set_minor_locator(mt.NullLocator())
    bot[0].set_ylabel("(model $-$ DEM)/SE")
    for k, ax in enumerate(list(top) + list(bot)):
        ax.text(0.0, 1.02, "(%s)" % "abcdefgh"[k], transform=ax.transAxes, ha="left", va="bottom",
                fontweight="bold")
    h = [Line2D([], [], color="0.15", marker=mk, mfc="white", ls="none", ms=3.5,
                label=r"DEM LAMMPS, %s ($\pm$2 SE)" % lab) for lab, mk in fd.sweeps]
    for m in fd.models:
        colour, dash = C.set_style(m.index)
        h.append(Line2D([], [], color=colour, ls=dash, lw=0.9, label=model_label(m.pset)))
    fig.legend(handles=h, loc="upper center", ncol=min(len(h), 4), bbox_to_anchor=(0.5, 1.0))
    fig.text(0.99, 0.005, r"EKM lines at $\dot\gamma$ = %s s$^{-1}$" % ", ".join("%g" % r for r in fd.rates),
             ha="right", va="bottom", fontsize=6)
    nrow = int(np.ceil(len(h) / 4))
    fig.tight_layout(rect=(0, 0.02, 1, 1 - 0.05 * nrow), w_pad=0.8, h_pad=0.3)
    writer.save(fig, "rheology_fit")
    return notes


def residuals(fd, m):
    """(panel, DemPoint, (model - DEM)/SE) of one set at every DEM point
    where it has a steady state: panel 0 mu, 1 phi (the model's phi at the
    point's I and rate), 2 P, 3 T; NaN where the SE is not finite."""
    d = float(np.mean([p.d for p in fd.dem]))
    out = []
    for p, s in zip(fd.dem, m.at):
        if s is None:
            continue
        I = p.rate * p.d / np.sqrt(p.P / fd.rho_p)
        with np.errstate(divide="ignore", invalid="ignore"):
            out += [(0, p, (float(s["mu"]) - p.mu) / p.mu_se),
                    (1, p, (phi_at_I(m, p.rate, I, d, fd.rho_p) - p.phi) / p.phi_se),
                    (2, p, (float(s["P"]) - p.P) / p.P_se),
                    (3, p, (num(s["T"]) - p.T) / p.T_se)]
    return out


def phi_at_I(m, rate, I, d, rho):
    """The model's phi at inertial number I and shear rate `rate`: the
    set's grid at that rate (I falls as phi rises), linear between grid
    points; NaN outside it."""
    c = model_curves(m, rate, d, rho)
    if c["phi"].size < 2:
        return np.nan
    order = np.argsort(c["I"])
    Is, ph = c["I"][order], c["phi"][order]
    if not Is[0] <= I <= Is[-1]:
        return np.nan
    return float(np.interp(I, Is, ph))


def make_phi_rate(data, writer):
    rows, lines, gd = data
    notes = []
    if len({(r[0], r[1]) for r in rows}) == 1:
        notes.append("%s: a single point (phi %.2f, rate %g/s): minimal rheology figure"
                     % (SCENARIO, rows[0][0], rows[0][1]))
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    phis = sorted({r[0] for r in rows})
    rates = sorted({r[1] for r in rows})
    colour = {p: C.POINT_COLOURS[i % len(C.POINT_COLOURS)] for i, p in enumerate(phis)}
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(C.PAGE_W, 2.6))
    lo, hi = gd[0], gd[-1]
    marker = {"liggghts": "o", "lammps": "s", "ekm": "D"}
    engines = []
    tops = []
    for p in phis:
        c = colour[p]
        # lines: the closed form of the thesis set (ekm homog), not a fit
        ok = [(g, s) for g, s in lines[p] if s is not None]
        if ok:
            a1.plot([g for g, _ in ok], [float(s["P"]) for _, s in ok], color=c, lw=0.9, zorder=1)
            a2.plot([g for g, _ in ok], [float(s["mu"]) for _, s in ok], color=c, lw=0.9, zorder=1)
            tops += [float(s["mu"]) for _, s in ok]
        else:
            notes.append("%s: phi %.2f: no steady homogeneous shear of the thesis set: no line" % (SCENARIO, p))
        for r in rows:
            if r[0] != p:
                continue
            src = r[2]
            if src != "ekm" and src not in engines:
                engines.append(src)
            kw = dict(color=c, marker=marker[src], ls="none", ms=4 if src != "ekm" else 4.5,
                      mfc=c if src != "ekm" else "white", mew=0.9, zorder=3 if src == "ekm" else 2)
            # the DEM markers sit 5% left of their rate, not to hide the EKM
            # marker (which stays on its rate, on its closed-form line)
            x = r[1] * (1.0 if src == "ekm" else 0.95)
            a1.errorbar([x], [r[3]], yerr=[2 * r[4]] if np.isfinite(r[4]) else None, **kw)
            a2.errorbar([x], [r[5]], yerr=[2 * r[6]] if np.isfinite(r[6]) else None, **kw)
    import matplotlib.ticker as mt
    plain = mt.FuncFormatter(lambda x, _p: "%g" % x)
    for ax in (a1, a2):
        ax.set_xscale("log")
        ax.set_xlim(lo, hi)
        ax.xaxis.set_major_locator(mt.FixedLocator(rates))   # the swept rates
        ax.xaxis.set_major_formatter(plain)
        ax.xaxis.set_minor_formatter(mt.NullFormatter())
        ax.set_xlabel(r"shear rate $\dot\gamma$ [s$^{-1}$]")
    a1.set_yscale("log")
    a1.yaxis.set_major_formatter(plain)
    a1.set_ylabel(r"pressure $P$ [Pa]")
    a2.set_ylabel(r"stress ratio $|\sigma_{xz}|/P$")
    tops += [r[5] + 2 * (r[6] if np.isfinite(r[6]) else 0) for r in rows if np.isfinite(r[5])]
    a2.set_ylim(0.0, 1.15 * max(tops) if tops else None)
    for ax, letter in ((a1, "(a)"), (a2, "(b)")):
        ax.text(0.0, 1.02, letter, transform=ax.transAxes, ha="left", va="bottom", fontweight="bold")
    h = [Line2D([], [], color="0.2", marker=marker[e], ls="none", ms=4,
                label=C.ENGINE_LABEL[e] + r" ($\pm$2 SE)") for e in engines]
    h.append(Line2D([], [], color="0.2", marker=marker["ekm"], mfc="white", ls="none", ms=4.5,
                    label=C.EKM_LABEL + " run"))
    h.append(Line2D([], [], color="0.2", lw=0.9, label="EKM closed form (thesis)"))
    h += [Line2D([], [], color=colour[p], lw=3, label=r"$\phi$ = %.2f" % p) for p in phis]
    fig.legend(handles=h, loc="upper center", ncol=min(len(h), 6), bbox_to_anchor=(0.5, 1.0))
    fig.tight_layout(rect=(0, 0, 1, 0.88 if len(h) <= 6 else 0.8), w_pad=1.5)
    writer.save(fig, "rheology_%s" % SCENARIO)
    return notes
