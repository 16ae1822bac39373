"""pilemaps.py: the figure of a 2D campaign scenario (the sand pile,
scenarios/sandpile.ini), one per sweep point: the maps the campaign scored
with `ekmcompare score2d`, DEM beside EKM on one colour scale per field.

Columns: each engine's coarse-grained map (its last window: the pile at
rest, [compare] cg_options), then the EKM's last frame with the scenario's
own [material] and with each fitted parameter set. Rows: the solid volume
fraction phi, the vertical normal stress sigma_zz (compression positive,
as score2d compares it; kPa), and one panel across the page with
sigma_zz along the lowest row of cells against x, every source (the base
of the pile: a dip under the apex would show there). Cells with phi below
PHI_VISIBLE x the largest phi are blank. Axes in units of the grain
diameter d (the cg outputs' mean_diameter), measured from the box's
centre line, where the source pours.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common as C  # noqa: E402

PHI_VISIBLE = 0.05   # a cell is drawn where phi > this x the largest phi of the figure


def _sources(pt, set_names):
    """[(key, label, Map2D)] in column order."""
    out = [(e, C.ENGINE_LABEL[e], pt.cg[e]) for e in C.ENGINES if e in pt.cg]
    if pt.ekm is not None:
        out.append(("ekm", C.EKM_LABEL + " (%s)" % C.THESIS, pt.ekm))
    order = {n: i for i, n in enumerate(set_names)}
    for n in sorted(pt.ekm_sets, key=lambda n: (order.get(n, len(order)), n)):
        out.append(("ekm_" + n, C.EKM_LABEL + " (%s)" % n, pt.ekm_sets[n]))
    return out


def _diameter(pt):
    """The grain diameter [m] of the cg outputs (None when there is none)."""
    import h5py
    ds = []
    for m in pt.cg.values():
        with h5py.File(m.path, "r") as f:
            if "mean_diameter" in f.attrs:
                ds.append(float(np.asarray(f.attrs["mean_diameter"]).reshape(-1)[0]))
    return float(np.mean(ds)) if ds else None


def _window(srcs, thr):
    """(x range, z top) [m] holding every source's material, a cell's margin."""
    xlo, xhi, ztop = np.inf, -np.inf, 0.0
    for _, _, m in srcs:
        on = m.val["phi"] > thr
        if not on.any():
            continue
        cols = np.where(on.any(axis=0))[0]
        rows = np.where(on.any(axis=1))[0]
        dx = m.x[1] - m.x[0] if m.x.size > 1 else 0.0
        dz = m.z[1] - m.z[0] if m.z.size > 1 else 0.0
        xlo = min(xlo, m.x[cols[0]] - 1.5 * dx)
        xhi = max(xhi, m.x[cols[-1]] + 1.5 * dx)
        ztop = max(ztop, m.z[rows[-1]] + 1.5 * dz)
    return xlo, xhi, ztop


def draw(srcs, d, title, writer, stem, meta):
    """The figure of srcs [(key, label, Map2D)]: key an engine (its colour
    and markers) or anything else (an EKM run, black, in line styles by
    order); d the grain diameter [m] of the axes (None: metres)."""
    import matplotlib.pyplot as plt
    from matplotlib.gridspec import GridSpec
    phimax = max(float(np.nanmax(m.val["phi"])) for _, _, m in srcs)
    thr = PHI_VISIBLE * phimax
    xlo, xhi, ztop = _window(srcs, thr)
    xc = 0.5 * (srcs[0][2].x[0] + srcs[0][2].x[-1])   # the box's centre line
    szz = {k: np.where(m.val["phi"] > thr, m.val["szz"], np.nan) * 1e-3 for k, _, m in srcs}
    smax = max(float(np.nanmax(v)) if np.isfinite(v).any() else 0.0 for v in szz.values())
    n = len(srcs)
    fig = plt.figure(figsize=(C.PAGE_W, 1.25 * 2 + 2.0))
    gs = GridSpec(3, n + 1, figure=fig, width_ratios=[1] * n + [0.05], height_ratios=[1, 1, 1.3])
    unit = d if d else 1.0
    ulabel = "/d" if d else " [m]"
    ims = [None, None]
    letters = "abcdefghijklmnopqrstuvwxyz"
    for j, (key, label, m) in enumerate(srcs):
        X, Z = (m.x - xc) / unit, m.z / unit
        phi = np.where(m.val["phi"] > thr, m.val["phi"], np.nan)
        for i, (v, vmax, cmap) in enumerate(((phi, phimax, "viridis"), (szz[key], smax, "magma"))):
            ax = fig.add_subplot(gs[i, j])
            ims[i] = ax.pcolormesh(X, Z, v, shading="nearest", cmap=cmap, vmin=0.0, vmax=vmax, rasterized=True)
            ax.set_xlim((xlo - xc) / unit, (xhi - xc) / unit)
            ax.set_ylim(0.0, ztop / unit)
            ax.tick_params(labelsize=6.5)
            if i == 0:
                ax.set_title(label, fontsize=7)
            if j == 0:
                ax.set_ylabel(r"$z%s$" % ulabel, fontsize=7)
            else:
                ax.tick_params(labelleft=False)
            if i == 1:
                ax.set_xlabel(r"$(x - x_c)%s$" % ulabel, fontsize=7)
            else:
                ax.tick_params(labelbottom=False)
            ax.text(0.04, 0.93, "(%s)" % letters[(i * n + j) % 26], transform=ax.transAxes,
                    fontsize=6.5, color="black", va="top")
    for i, lab in enumerate((r"$\phi$", r"$\sigma_{zz}$ [kPa]")):
        cb = fig.colorbar(ims[i], cax=fig.add_subplot(gs[i, n]))
        cb.set_label(lab, fontsize=7)
        cb.ax.tick_params(labelsize=6.5)
    # the base: sigma_zz in the lowest row of cells
    ax = fig.add_subplot(gs[2, :n])
    dashes = ["-"] + C.SET_DASHES   # the EKM runs in order: solid, then the sets'
    j = 0
    for key, label, m in srcs:
        row = szz[key][0]
        if key in C.ENGINE_COLOUR:
            ax.plot((m.x - xc) / unit, row, color=C.ENGINE_COLOUR[key], lw=0.9,
                    ls="-" if key == "liggghts" else "--", marker="o" if key == "liggghts" else "s",
                    ms=2.5, mfc="white", label=label)
        else:
            ax.plot((m.x - xc) / unit, row, color=C.EKM_COLOUR, ls=dashes[j % len(dashes)], lw=1.3, label=label)
            j += 1
    ax.set_xlim((xlo - xc) / unit, (xhi - xc) / unit)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel(r"$(x - x_c)%s$" % ulabel, fontsize=7)
    z0 = srcs[0][2].z[0] / unit
    ax.set_ylabel(r"$\sigma_{zz}$ [kPa], lowest row" + "\n" + (r"($z = %.3g\,d$)" % z0 if d else
                                                             r"($z = %.3g$ m)" % z0), fontsize=7)
    ax.tick_params(labelsize=6.5)
    ax.legend(fontsize=6.5, ncol=min(n, 4), loc="upper center", bbox_to_anchor=(0.5, -0.32))
    ax.text(0.01, 0.93, "(%s)" % letters[(2 * n) % 26], transform=ax.transAxes, fontsize=6.5, va="top")
    fig.suptitle(title, fontsize=7.5)
    fig.tight_layout(rect=(0, 0.0, 1, 0.97), h_pad=0.4, w_pad=0.3)
    writer.save(fig, stem, meta)


def pile_figure(sc, pt, writer, stem, set_names):
    srcs = _sources(pt, set_names)
    title = ("%s%s: at rest, the DEM's last window (t = %s s) and the EKM's last frame (t = %s s)"
             % (sc.name, " " + pt.name if pt.name else "",
                "/".join("%.3g" % pt.cg[e].t for e in C.ENGINES if e in pt.cg) or "-",
                "%.3g" % pt.ekm.t if pt.ekm is not None else "-"))
    draw(srcs, _diameter(pt), title, writer, stem,
         {"Title": "%s %s: phi and sigma_zz maps, DEM and EKM" % (sc.name, pt.name),
          "Subject": "; ".join(C.rel(m.path) for _, _, m in srcs)})


def make(scenarios, writer, set_names):
    notes = []
    for sc in scenarios:
        if not sc.twod:
            continue
        if "phi" not in sc.fields or "szz" not in sc.fields:
            notes.append("%s: scored without phi and szz: no maps" % sc.name)
            continue
        for pt in sc.points:
            if not pt.cg and pt.ekm is None:
                continue
            pile_figure(sc, pt, writer, "maps_%s%s" % (sc.name, "_" + pt.name if pt.name else ""), set_names)
    return notes


def main(argv=None):
    """pilemaps.py OUT_STEM --map ENGINE=MAPS.h5:GROUP ... --ekm LABEL=RUN.h5 ...
    [--time T] [--d D] [--title TEXT]: the same figure from a pile-map file's
    groups (results/sandpile/maps-SIZE.h5, the ensembles' mean maps) and ekm
    2D runs at --time T (default their last frame): OUT_STEM.pdf and .png.
    Exit status: 0; 1 usage; 2 an input not as expected; 3 an input missing
    or an output that cannot be written (one line naming it)."""
    import argparse
    ap = argparse.ArgumentParser(prog="pilemaps.py", description=main.__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--map", action="append", default=[])
    ap.add_argument("--ekm", action="append", default=[])
    ap.add_argument("--time", type=float, default=None)
    ap.add_argument("--d", type=float, default=0.002)
    ap.add_argument("--title", default="")
    try:
        a = ap.parse_args(argv)
    except SystemExit as e:
        return 1 if e.code else 0
    bad = [v for v in a.map + a.ekm if "=" not in v] + [v for v in a.map if ":" not in v.split("=", 1)[-1]]
    if bad or not (a.map or a.ekm):
        print("pilemaps.py: expected --map ENGINE=MAPS.h5:GROUP and --ekm LABEL=RUN.h5, got %s"
              % (bad[0] if bad else "neither"), file=sys.stderr)
        return 1
    fields = ["phi", "szz"]
    try:
        srcs = []
        for v in a.map:
            key, spec = v.split("=", 1)
            path, group = spec.rsplit(":", 1)
            srcs.append((key, C.ENGINE_LABEL.get(key, key), C.Map2D(path, fields, "a DEM map group", False,
                                                                     group=group)))
        for v in a.ekm:
            label, path = v.split("=", 1)
            srcs.append(("ekm_" + label, "%s (%s)" % (C.EKM_LABEL, label),
                         C.Map2D(path, fields, "an ekm 2D run", True, time=a.time)))
    except C.InputError as e:
        print("pilemaps.py: %s" % e, file=sys.stderr)
        return e.status
    C.style()
    w = C.Writer(os.path.dirname(os.path.abspath(a.out)))
    try:
        draw(srcs, a.d, a.title, w, os.path.basename(a.out),
             {"Title": a.title or "phi and sigma_zz maps, DEM and EKM",
              "Subject": "; ".join(C.rel(m.path) for _, _, m in srcs)})
    except OSError as e:
        print("pilemaps.py: %s: cannot write (%s)" % (e.filename or a.out, e.strerror), file=sys.stderr)
        return 3
    print("pilemaps.py: %s.pdf, .png" % a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
