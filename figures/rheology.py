"""rheology.py: figure 3, simple-shear rheology: P and |sxz|/P against
the shear rate at each phi. DEM (LAMMPS; Lees-Edwards) points with error
bars, the EKM runs at the same points, and the EKM's closed form for steady
homogeneous simple shear (../shared/MODEL.md section 7) as lines.

A point's phi and shear rate are its sweep variables phi and rate in the
score table (each row's `vars`: the resolved scenario's points[].vars, as
the campaign's table.sh writes them); the figures do not map the rate to
wall velocities themselves.

DEM values are the spatial means of the steady profiles (the flow is
homogeneous); their SE is the mean of the profile's SEs, which assumes the
bins fully correlated (the kernel is a grain diameter wide, bins are half
of that apart): an upper bound. The EKM value is the mean over the cells
of its last output (walls at -+V/2; the steady state is homogeneous).
The DEM markers are drawn 5% left of their shear rate so as not to hide the
EKM's, which stay on their rate (and on the closed-form line).

Figure 3b (rheology_simple_shear_p), when the pressure-controlled sweep
simple_shear_p has results: the DEM points of both simple-shear sweeps
(fixed volume, fixed normal stress) in the inertial-number plane, mu =
|sxz|/P and phi against I = rate d / sqrt(P / rho_p), with P the DEM's mean
pressure and d the CG's mean diameter; the line is the EKM's closed form
below phi_co (MODEL.md 7): I = d sqrt(3 eps0 (1 - phi/phi_cp) / (2 eta0)),
mu = sqrt(3 eta0 eps0 / (2 phi)). A pressure point's EKM run is a
fixed-gap run at its rate and [initial] phi (the EKM has no pressure-held
wall yet): it is not drawn.
"""

import re

import numpy as np

import common as C

SCENARIO = "simple_shear"
SCENARIO_P = "simple_shear_p"


def closed_form_P(m, phi, gdot):
    """The closed form of MODEL.md section 7 (steady homogeneous simple
    shear): P = rho_p g(phi) [2 eta0 gdot^2 / (3 eps0) + T0 (phi - phi_co)_+]
    with g(phi) = 1 / (1 - phi/phi_cp), the solver's contact factor
    (continuum/model.c ekm_g)."""
    g = 1.0 / (1.0 - phi / m["phi_cp"])
    return m["rho_p"] * g * (2 * m["eta0"] * gdot ** 2 / (3 * m["eps0"])
                             + m["T0"] * max(phi - m["phi_co"], 0.0))


def closed_form_mu(m, phi):
    """The closed form of MODEL.md section 7 for nu = 1:
    |sxz| / P = sqrt(3 eta0 eps0 / (2 phi)), independent of the rate."""
    return np.sqrt(3 * m["eta0"] * m["eps0"] / (2 * phi))


MATERIAL = ("rho_p", "phi_co", "phi_cp", "T0", "eta0", "eps0", "nu")


def point_rate(pt):
    """Shear rate [1/s] of a point: from its tag (...-rate<R>), else (a
    single case) from its EKM run's walls."""
    m = re.fullmatch(r"(phi|p)([0-9.eE+-]+)-rate([0-9.eE+-]+)", pt.name)
    if m:
        return float(m.group(3))
    e = pt.ekm
    why = "the shear rate of the single simple-shear case"
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


def collect(sc):
    """Rows (phi, rate, source, P, P_se, mu, mu_se) and the material."""
    rows, mat = [], None
    for pt in sc.points:
        if pt.ekm is None:
            continue
        phi, rate = point_state(pt)
        if mat is None:
            mat = {k: pt.ekm.number("material." + k, "the closed-form rheology lines")
                   for k in MATERIAL}
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
    return rows, mat


def inertial_rows(sc):
    """DEM rows (engine, I, mu, mu_se, phi, phi_se) of a simple-shear
    scenario's points, and the material (None without an EKM run)."""
    rows, mat = [], None
    for pt in sc.points:
        if pt.ekm is None:
            continue
        if mat is None:
            mat = {k: pt.ekm.number("material." + k, "the closed-form rheology lines") for k in MATERIAL}
        rate = point_rate(pt)
        for e, cg in pt.cg.items():
            P, Pse = dem_mean(cg, "P")
            S, Sse = dem_mean(cg, "sxz")
            ph, phse = dem_mean(cg, "phi")
            S = abs(S)
            if not (P > 0 and S > 0):
                continue
            mu = S / P
            rows.append((e, rate * cg.d / np.sqrt(P / mat["rho_p"]), mu,
                         mu * np.sqrt((Sse / S) ** 2 + (Pse / P) ** 2), ph, phse, cg.d))
    return rows, mat


def make_inertial(scenarios, writer):
    """Figure 3b: mu(I) and phi(I) of both simple-shear sweeps."""
    sp = next((s for s in scenarios if s.name == SCENARIO_P), None)
    if sp is None:
        return []
    if not all(f in sp.fields for f in ("phi", "P", "sxz")):
        return ["%s: phi, P and sxz are not all scored: no inertial-number figure" % SCENARIO_P]
    sets = []
    mat = None
    for name, label, mk in ((SCENARIO, "fixed volume", "s"), (SCENARIO_P, "fixed normal stress", "o")):
        sc = next((s for s in scenarios if s.name == name), None)
        if sc is None or not all(f in sc.fields for f in ("phi", "P", "sxz")):
            continue
        rows, m = inertial_rows(sc)
        if rows:
            sets.append((label, mk, rows))
            mat = mat or m
    if not any(lab == "fixed normal stress" for lab, _m, _r in sets):
        return ["%s: no DEM profiles with an EKM run: no inertial-number figure" % SCENARIO_P]
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(C.PAGE_W, 2.6))
    colours = {"fixed volume": C.POINT_COLOURS[0], "fixed normal stress": C.POINT_COLOURS[1 % len(C.POINT_COLOURS)]}
    Is = []
    for label, mk, rows in sets:
        c = colours[label]
        for (_e, I, mu, mu_se, ph, phse, _d) in rows:
            kw = dict(color=c, marker=mk, ls="none", ms=4, mew=0.9, zorder=2)
            a1.errorbar([I], [mu], yerr=[2 * mu_se] if np.isfinite(mu_se) else None, **kw)
            a2.errorbar([I], [ph], yerr=[2 * phse] if np.isfinite(phse) else None, **kw)
            Is.append(I)
    notes = []
    d = sets[0][2][0][6]
    # the EKM closed form below phi_co (MODEL.md 7): I(phi), mu(phi)
    ph = np.linspace(0.30, mat["phi_co"], 80, endpoint=False)
    I_line = d * np.sqrt(3 * mat["eps0"] * (1 - ph / mat["phi_cp"]) / (2 * mat["eta0"]))
    if mat["nu"] == 1.0:
        a1.plot(I_line, closed_form_mu(mat, ph), color="0.2", lw=0.9, zorder=1)
    else:
        notes.append("%s: material.nu = %g: no closed form for |sxz|/P (MODEL.md 7 has nu = 1)"
                     % (SCENARIO_P, mat["nu"]))
    a2.plot(I_line, ph, color="0.2", lw=0.9, zorder=1)
    lo, hi = min(Is + [I_line.min()]) / 1.5, max(Is + [I_line.max()]) * 1.5
    for ax in (a1, a2):
        ax.set_xscale("log")
        ax.set_xlim(lo, hi)
        ax.set_xlabel(r"inertial number $I = \dot\gamma d / \sqrt{P/\rho_p}$")
    a1.set_ylabel(r"stress ratio $|\sigma_{xz}|/P$")
    a2.set_ylabel(r"volume fraction $\phi$")
    for ax, letter in ((a1, "(a)"), (a2, "(b)")):
        ax.text(0.0, 1.02, letter, transform=ax.transAxes, ha="left", va="bottom", fontweight="bold")
    h = [Line2D([], [], color=colours[lab], marker=mk, ls="none", ms=4,
                label="%s, %s" % (C.ENGINE_LABEL["lammps"] if rows[0][0] == "lammps" else C.ENGINE_LABEL[rows[0][0]],
                                  lab) + r" ($\pm$2 SE)") for lab, mk, rows in sets]
    h.append(Line2D([], [], color="0.2", lw=0.9, label=r"EKM closed form ($\phi < \phi_{co}$)"))
    fig.legend(handles=h, loc="upper center", ncol=len(h), bbox_to_anchor=(0.5, 1.0))
    fig.tight_layout(rect=(0, 0, 1, 0.88), w_pad=1.5)
    writer.save(fig, "rheology_%s" % SCENARIO_P)
    return notes


def make(scenarios, writer):
    return make_phi_rate(scenarios, writer) + make_inertial(scenarios, writer)


def make_phi_rate(scenarios, writer):
    sc = next((s for s in scenarios if s.name == SCENARIO), None)
    if sc is None:
        return []
    if not ("P" in sc.fields and "sxz" in sc.fields):
        return ["%s: P and sxz are not scored: no rheology figure" % SCENARIO]
    rows, mat = collect(sc)
    if not rows:
        return ["%s: no EKM run: no rheology figure" % SCENARIO]
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
    lo, hi = min(rates) / 1.5, max(rates) * 1.5
    gd = np.geomspace(lo, hi, 60)
    marker = {"liggghts": "o", "lammps": "s", "ekm": "D"}
    engines = []
    for p in phis:
        c = colour[p]
        # lines: the closed form (MODEL.md 7), not a fit
        a1.plot(gd, [closed_form_P(mat, p, g) for g in gd], color=c, lw=0.9, zorder=1)
        if mat["nu"] == 1.0:
            a2.plot(gd, np.full_like(gd, closed_form_mu(mat, p)), color=c, lw=0.9, zorder=1)
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
    if mat["nu"] != 1.0:
        notes.append("%s: material.nu = %g: no closed form for |sxz|/P (MODEL.md 7 has nu = 1)"
                     % (SCENARIO, mat["nu"]))
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
    tops = [r[5] + 2 * (r[6] if np.isfinite(r[6]) else 0) for r in rows if np.isfinite(r[5])]
    if mat["nu"] == 1.0:
        tops += [closed_form_mu(mat, p) for p in phis]
    a2.set_ylim(0.0, 1.15 * max(tops) if tops else None)
    for ax, letter in ((a1, "(a)"), (a2, "(b)")):
        ax.text(0.0, 1.02, letter, transform=ax.transAxes, ha="left", va="bottom", fontweight="bold")
    h = [Line2D([], [], color="0.2", marker=marker[e], ls="none", ms=4,
                label=C.ENGINE_LABEL[e] + r" ($\pm$2 SE)") for e in engines]
    h.append(Line2D([], [], color="0.2", marker=marker["ekm"], mfc="white", ls="none", ms=4.5,
                    label=C.EKM_LABEL + " run"))
    h.append(Line2D([], [], color="0.2", lw=0.9, label="EKM closed form"))
    h += [Line2D([], [], color=colour[p], lw=3, label=r"$\phi$ = %.2f" % p) for p in phis]
    fig.legend(handles=h, loc="upper center", ncol=min(len(h), 6), bbox_to_anchor=(0.5, 1.0))
    fig.tight_layout(rect=(0, 0, 1, 0.88 if len(h) <= 6 else 0.8), w_pad=1.5)
    writer.save(fig, "rheology_%s" % SCENARIO)
    return notes
