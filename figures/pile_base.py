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

Writes OUT_STEM.pdf, OUT_STEM.png and OUT_STEM.csv (every curve drawn:
source, what, x [m], p [Pa], se [Pa] (the DEM's; empty for the EKM)), each
under a temporary name renamed when complete. Exit status: 0; 1 usage; 2 an
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
    return x, pr.mean(axis=0), pr.std(axis=0, ddof=1) / np.sqrt(runs), runs


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
    C.style()
    fig, axes = plt.subplots(1, len(sources), figsize=(C.PAGE_W, 3.2), sharey=True, squeeze=False)
    rows = []
    dashes = ["-"] + C.SET_DASHES
    for k, src in enumerate(sources):
        ax = axes[0][k]
        for s, e, (x, p, se, runs) in dem:
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
    except OSError as e:
        print("%s: %s: cannot write (%s)" % (PROG, e.filename or a.out, e.strerror), file=sys.stderr)
        return 3
    plt.close(fig)
    print("%s: %s.pdf, .png, .csv" % (PROG, a.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
