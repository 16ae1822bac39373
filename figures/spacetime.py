"""spacetime.py: figure 2, a time-series scenario (filling): space-time
maps phi(z, t) of each DEM engine and the EKM on one colour scale, and the
bed height h(t) of all of them in one panel.

Bed height: h(t) is the highest z where phi(z, t) exceeds half the bed's
bulk value phi_bed, linearly interpolated between the grid points around
the crossing; phi_bed is the largest phi of the source's last profile (the
settled bed), each source its own (the EKM bed packs at phi_co..phi_cp, the
DEM's at its own random packing). h = 0 before there is a bed.
"""
import numpy as np

import common as C


def bed_height(zt, phi, phi_bed):
    """h(t) [m] for phi [nt][nz] on the grid zt [nt][nz] of each time (see the
    module comment)."""
    thr = 0.5 * phi_bed
    h = np.zeros(phi.shape[0])
    for i, row in enumerate(phi):
        z = zt[i]
        above = np.nonzero(np.nan_to_num(row) > thr)[0]
        if above.size == 0:
            continue
        j = above[-1]
        if j + 1 < z.size and row[j + 1] < row[j]:
            # crossing between j and j+1
            h[i] = z[j] + (row[j] - thr) / (row[j] - row[j + 1]) * (z[j + 1] - z[j])
        else:
            h[i] = z[j]
    return h


def _sources(pt):
    """(key, label, z [nt][nz] (the grid of each time) [m], t [s], phi
    [nt][nz]) of each engine, then EKM."""
    out = []
    for e, cg in pt.cg.items():
        z = np.tile(cg.z + cg.shift, (cg.t.size, 1))
        out.append((e, C.ENGINE_LABEL[e], z, cg.t, cg.val["phi"]))
    out.append(("ekm", C.EKM_LABEL, pt.ekm.zt, pt.ekm.t, pt.ekm.val["phi"]))
    return out


def maps_figure(sc, pt, writer, stem):
    import matplotlib.pyplot as plt
    srcs = _sources(pt)
    d = float(np.mean([c.d for c in pt.cg.values()]))
    vmax = max(float(np.nanmax(s[4])) for s in srcs)
    vmax = np.ceil(vmax * 20) / 20          # to 0.05 above the densest
    n = len(srcs)
    fig, axes = plt.subplots(1, n + 1, figsize=(C.PAGE_W, 2.3), squeeze=False,
                             gridspec_kw=dict(width_ratios=[1] * n + [0.06]))
    axes = axes[0]
    zmax = max(float(np.max(s[2])) for s in srcs)
    tmax = max(s[3][-1] for s in srcs)
    im = None
    for k, (ax, (key, label, z, t, phi)) in enumerate(zip(axes[:n], srcs)):
        # DEM windows are drawn as blocks around their mid-times
        # each time's column on that time's grid (a moving wall moves it)
        im = ax.pcolormesh(np.tile(t, (z.shape[1], 1)), z.T / d, phi.T, shading="nearest", cmap="viridis",
                           vmin=0.0, vmax=vmax, rasterized=True)
        ax.set_xlim(0.0, tmax)
        ax.set_ylim(0.0, zmax / d)
        ax.set_xlabel(r"$t$ [s]")
        if k == 0:
            ax.set_ylabel(r"$z/d$  ($d$ = %.2f mm)" % (d * 1e3))
        else:
            ax.tick_params(labelleft=False)
        ax.text(0.04, 0.96, "(%s) %s" % ("abcdefgh"[k], label), transform=ax.transAxes,
                ha="left", va="top", fontsize=7, color="white")
        ax.tick_params(color="white", which="both")
    cb = fig.colorbar(im, cax=axes[n])
    cb.set_label(r"solid volume fraction $\phi$")
    cb.ax.tick_params(direction="out", right=True, left=False, color="black")
    fig.tight_layout(w_pad=0.4)
    writer.save(fig, stem)


def height_figure(sc, pt, writer, stem):
    import matplotlib.pyplot as plt
    srcs = _sources(pt)
    d = float(np.mean([c.d for c in pt.cg.values()]))
    fig, ax = plt.subplots(figsize=(C.COLUMN_W, 2.4))
    for key, label, z, t, phi in srcs:
        phi_bed = float(np.nanmax(phi[-1]))
        h = bed_height(z, phi, phi_bed)
        if key == "ekm":
            ax.plot(t, h / d, color=C.EKM_COLOUR, lw=1.3, label=label, zorder=3)
        else:
            ax.plot(t, h / d, color=C.ENGINE_COLOUR[key], lw=0.9,
                    ls="-" if key == "liggghts" else "--", marker="o" if key == "liggghts" else "s",
                    ms=3, mfc="white", label=label)
    ts = pt.ekm.attrs.get("top.t_stop")
    try:
        ts = float(ts)
    except (TypeError, ValueError):
        ts = None
    if ts is not None and 0 < ts < pt.ekm.t[-1]:
        ax.axvline(ts, color="0.6", lw=0.6, ls=":", zorder=0)
        ax.text(ts, 0.02, "inflow stops ", transform=ax.get_xaxis_transform(),
                ha="right", va="bottom", fontsize=6.5, color="0.4")
    ax.set_xlabel(r"$t$ [s]")
    ax.set_ylabel("bed height $h/d$\n" + r"(highest $z$ with $\phi > \phi_{\rm bed}/2$)")
    ax.set_xlim(0.0, max(s[3][-1] for s in srcs))
    ax.set_ylim(bottom=0.0)
    ax.legend(loc="lower right")
    fig.tight_layout()
    writer.save(fig, stem)


def make(scenarios, writer):
    for sc in scenarios:
        if sc.steady or "phi" not in sc.fields:
            continue
        for pt in sc.points:
            if not pt.cg or pt.ekm is None:
                continue
            suffix = ("_%s" % pt.name) if pt.name else ""
            maps_figure(sc, pt, writer, "%s_phi_map%s" % (sc.name, suffix))
            height_figure(sc, pt, writer, "%s_bed_height%s" % (sc.name, suffix))
