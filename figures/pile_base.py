#!/usr/bin/python3
"""pile_base.py: the base pressure p(x) under the sand piles at rest, the
DEM ensembles of both engines with their bands beside the EKM's piles, one
panel per source (issue 34, item 5).

    /usr/bin/python3 figures/pile_base.py OUT_STEM --dem SOURCE:ENGINE=BASE.h5 ...
        [--ekm SOURCE:LABEL=RUN.h5 ...] [--time T]

--dem: a group file of scripts/dem/pile_analysis.sh
(results/sandpile/base-<law>-<engine>-<source>-<size>.h5: x [m], the runs'
profiles p_base_runs [runs][bins], [Pa]); each run's profile averaged
over --merge K adjacent bins (default 2: the files' 2 d bins to 4 d), then
drawn as the mean over the runs with a band of +-2 SE (sd / sqrt(runs)).
--ekm: an ekm 2D run of the same pile (scripts/dem/pile_ekm.sh); its frame
at --time T [s] (default the last): the normal stress on its lowest row of
cells, -szz (compression positive) where the cell holds material (phi >
PHI_MATERIAL), against x. SOURCE is the panel (hopper, sieve), in order of
first appearance. The abscissa is x - x_c in grain diameters d (x_c the
box's middle, where the sources pour; d from --d, default 2 mm).

Writes OUT_STEM.pdf, OUT_STEM.png, OUT_STEM.csv (every curve drawn:
source, what, x [m], p [Pa], se [Pa] (the DEM's; empty for the EKM)) and
OUT_STEM.json: per source and EKM pile, the relative L2 error of its base
pressure (its cells averaged over each DEM bin) against each engine's mean
over the bins where both have material, with a jackknife SE over the
DEM's piles, the bins used and those left out; and the engine floor
(LIGGGHTS's mean against LAMMPS's, both jackknife SEs in quadrature).
Each is written under a temporary name renamed when complete. Exit status: 0; 1 usage; 2 an
input not as expected (one line naming it); 3 an input missing or an output
that cannot be written; 7 numpy, h5py or matplotlib missing.
"""
import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

PROG = "pile_base.py"
PHI_MATERIAL = 0.05   # an EKM cell with less is empty (its stress not drawn)


class Bad(Exception):
    def __init__(self, msg, status=2):
        super().__init__(msg)
        self.status = status


def spec(s):
    """SOURCE:NAME=FILE -> (source, name, file)."""
    if "=" not in s or ":" not in s.split("=", 1)[0]:
        raise argparse.ArgumentTypeError("expected SOURCE:NAME=FILE, got '%s'" % s)
    key, path = s.split("=", 1)
    source, name = key.split(":", 1)
    if not source or not name or not path:
        raise argparse.ArgumentTypeError("expected SOURCE:NAME=FILE, got '%s'" % s)
    return source, name, path


def read_dem(path, merge):
    import h5py
    import numpy as np
    if not os.path.isfile(path):
        raise Bad("%s: missing (a base group file of scripts/dem/pile_analysis.sh)" % path, 3)
    with h5py.File(path, "r") as f:
        for n in ("x", "p_base_runs"):
            if n not in f:
                raise Bad("%s: dataset /%s: missing (a base group file of pile_analysis.sh)" % (path, n))
        x = np.asarray(f["x"][()], float)
        pr = np.asarray(f["p_base_runs"][()], float)
    if not (x.ndim == 1 and pr.ndim == 2 and pr.shape[1] == x.size and pr.shape[0] >= 2):
        raise Bad("%s: /x, /p_base_runs: expected x [bins] and at least 2 runs' profiles [runs][bins]" % path)
    n = x.size // merge * merge
    x = x[:n].reshape(-1, merge).mean(axis=1)
    pr = pr[:, :n].reshape(pr.shape[0], -1, merge).mean(axis=2)
    runs = pr.shape[0]
    return x, pr.mean(axis=0), pr.std(axis=0, ddof=1) / np.sqrt(runs), runs, pr


def on_bins(xm, pm, xb):
    """The model curve (xm, pm) averaged over the cells whose centres lie
    in each bin of centres xb (bins of equal width); NaN where a bin holds
    no cell or an empty one."""
    import numpy as np
    w = xb[1] - xb[0] if xb.size > 1 else np.inf
    out = np.full(xb.size, np.nan)
    for k, c in enumerate(xb):
        sel = np.abs(xm - c) < 0.5 * w * (1 - 1e-9)
        if sel.any() and np.all(np.isfinite(pm[sel])):
            out[k] = pm[sel].mean()
    return out


def rel_l2(model, runs):
    """||model - mean(runs)|| / ||mean(runs)|| over the bins where the DEM's
    mean is above 0 and the model has material, with its jackknife SE over
    the runs (the same bins), the bins used and the DEM bins with material
    the model has none at."""
    import numpy as np
    mean = runs.mean(axis=0)
    on = (mean > 0) & np.isfinite(model)
    left = int(np.sum((mean > 0) & ~np.isfinite(model)))

    if not on.any():
        return {"rel_l2": None, "se": None, "bins": 0, "bins_left_out": left}

    def r(ref):
        return float(np.linalg.norm(model[on] - ref[on]) / np.linalg.norm(ref[on]))
    n = runs.shape[0]
    jack = np.array([r(np.delete(runs, i, axis=0).mean(axis=0)) for i in range(n)])
    se = float(np.sqrt((n - 1) / n * np.sum((jack - jack.mean()) ** 2)))
    return {"rel_l2": r(mean), "se": se, "bins": int(on.sum()), "bins_left_out": left}


def read_ekm(path, time):
    import h5py
    import numpy as np
    if not os.path.isfile(path):
        raise Bad("%s: missing (an ekm 2D run)" % path, 3)
    with h5py.File(path, "r") as f:
        for n in ("x", "t", "phi", "szz"):
            if n not in f:
                raise Bad("%s: dataset /%s: missing (an ekm 2D run with the solid regime's stress)" % (path, n))
        t = np.asarray(f["t"][()], float)
        i = t.size - 1 if time is None else int(np.argmin(np.abs(t - time)))
        if time is not None and abs(t[i] - time) > 1e-9:
            raise Bad("%s: no output at t = %g s (nearest %g s)" % (path, time, t[i]))
        phi = np.asarray(f["phi"][i], float)
        szz = np.asarray(f["szz"][i], float)
        x = np.asarray(f["x"][()], float)
    if phi.ndim != 2 or phi.shape[1] != x.size:
        raise Bad("%s: /phi: expected [nt][nz][nx] (a 2D run)" % path)
    p = np.where(phi[0] > PHI_MATERIAL, -szz[0], np.nan)
    return x, p, float(t[i])


def write_atomic(path, write):
    tmp = os.path.join(os.path.dirname(path) or ".", "." + os.path.basename(path) + ".tmp")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def main(argv=None):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--dem", type=spec, action="append", default=[], required=True)
    ap.add_argument("--ekm", type=spec, action="append", default=[])
    ap.add_argument("--time", type=float, default=None)
    ap.add_argument("--d", type=float, default=0.002)
    ap.add_argument("--merge", type=int, default=2)
    try:
        a = ap.parse_args(argv)
    except SystemExit as e:
        return 1 if e.code else 0
    try:
        import numpy as np
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import h5py  # noqa: F401
    except ImportError as e:
        print("%s: %s (apt-get install python3-numpy python3-h5py python3-matplotlib)" % (PROG, e),
              file=sys.stderr)
        return 7
    import common as C
    try:
        sources = []
        for s, _, _ in a.dem + a.ekm:
            if s not in sources:
                sources.append(s)
        if a.merge < 1:
            raise Bad("--merge %d: expected a bin count >= 1" % a.merge)
        dem = [(s, e, read_dem(p, a.merge)) for s, e, p in a.dem]
        ekm = [(s, n, read_ekm(p, a.time)) for s, n, p in a.ekm]
    except Bad as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return e.status
    scores = {}
    for src in sources:
        sd = {e: d for s, e, d in dem if s == src}
        entry = {"ekm": {}, "floor": None}
        for s, n, (x, p, t) in ekm:
            if s == src:
                entry["ekm"][n] = {e: rel_l2(on_bins(x, p, d[0]), d[4]) for e, d in sd.items()}
        if "lammps" in sd and "liggghts" in sd and np.allclose(sd["lammps"][0], sd["liggghts"][0]):
            # the engine floor: LIGGGHTS's mean against LAMMPS's piles, and
            # the jackknife over LIGGGHTS's piles added in quadrature
            lig = rel_l2(sd["liggghts"][1], sd["lammps"][4])
            lam = rel_l2(sd["lammps"][1], sd["liggghts"][4])
            if lig["se"] is not None:
                lig["se"] = float(np.hypot(lig["se"], lam["se"]))
            entry["floor"] = lig
        scores[src] = entry
    C.style()
    fig, axes = plt.subplots(1, len(sources), figsize=(C.PAGE_W, 3.2), sharey=True, squeeze=False)
    rows = []
    dashes = ["-"] + C.SET_DASHES
    for k, src in enumerate(sources):
        ax = axes[0][k]
        for s, e, (x, p, se, runs, _) in dem:
            if s != src:
                continue
            xc = 0.5 * (x[0] + x[-1])
            colour = C.ENGINE_COLOUR.get(e, "0.4")
            ax.fill_between((x - xc) / a.d, p - 2 * se, p + 2 * se, color=colour, alpha=0.25, lw=0)
            ax.plot((x - xc) / a.d, p, color=colour, lw=1.0,
                    label="%s (%d piles, +-2 SE)" % (C.ENGINE_LABEL.get(e, e), runs))
            rows += [(s, "DEM " + e, xi, pi, si) for xi, pi, si in zip(x, p, se)]
        j = 0
        for s, n, (x, p, t) in ekm:
            if s != src:
                continue
            xc = 0.5 * (x[0] + x[-1])
            ax.plot((x - xc) / a.d, p, color=C.EKM_COLOUR, ls=dashes[j % len(dashes)], lw=1.2,
                    label="%s %s (t = %g s)" % (C.EKM_LABEL, n, t))
            rows += [(s, "EKM " + n, xi, pi, float("nan")) for xi, pi in zip(x, p)]
            j += 1
        ax.set_title(src, fontsize=8)
        ax.set_xlabel(r"$(x - x_c)/d$")
        if k == 0:
            ax.set_ylabel(r"base pressure $p$ [Pa]")
        ax.set_ylim(bottom=0.0)
        ax.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2)
        ax.text(0.02, 0.96, "(%s)" % "abcdef"[k], transform=ax.transAxes, va="top", fontsize=7)
    fig.tight_layout()
    try:
        os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
        for ext in ("pdf", "png"):
            write_atomic("%s.%s" % (a.out, ext),
                         lambda tmp, ext=ext: fig.savefig(tmp, format=ext, dpi=300,
                                                          metadata={"CreationDate": None} if ext == "pdf" else {}))

        def csv(tmp):
            with open(tmp, "w") as fh:
                fh.write("# %s: the curves of %s.pdf; p: the DEM's mean floor pressure over its piles "
                         "(se over piles) or the EKM's -szz in its lowest row of cells\n"
                         % (PROG, os.path.basename(a.out)))
                fh.write("source,what,x_m,p_Pa,se_Pa\n")
                for s, w, xi, pi, si in rows:
                    fh.write("%s,%s,%.9g,%s,%s\n" % (s, w, xi, "" if pi != pi else "%.9g" % pi,
                                                     "" if si != si else "%.9g" % si))
        write_atomic(a.out + ".csv", csv)

        def js(tmp):
            import json
            with open(tmp, "w") as fh:
                json.dump({"program": PROG, "definition": "relative L2 of the EKM's base pressure (its "
                           "lowest row's -szz averaged over each DEM bin) against the DEM's mean over "
                           "its piles, over the bins where both have material; se: jackknife over the "
                           "DEM's piles; floor: LIGGGHTS's mean against LAMMPS's (jackknife SEs of "
                           "both in quadrature)", "bin_width_m": None if not dem else
                           float(dem[0][2][0][1] - dem[0][2][0][0]), "time_s": a.time,
                           "sources": scores}, fh, indent=1, allow_nan=False)
                fh.write("\n")
        write_atomic(a.out + ".json", js)
    except OSError as e:
        print("%s: %s: cannot write (%s)" % (PROG, e.filename or a.out, e.strerror), file=sys.stderr)
        return 3
    plt.close(fig)
    for src, entry in scores.items():
        for n, vs in entry["ekm"].items():
            print("%s: %s, EKM %s: base p rel. L2 %s" % (PROG, src, n, ", ".join(
                ("%.3f +- %.3f against %s" % (v["rel_l2"], v["se"], e)) if v["rel_l2"] is not None
                else "none against %s (no common bin)" % e for e, v in vs.items())))
        if entry["floor"]:
            print("%s: %s, engine floor: %.3f +- %.3f" % (PROG, src, entry["floor"]["rel_l2"], entry["floor"]["se"]))
    print("%s: %s.pdf, .png, .csv, .json" % (PROG, a.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
