"""pile_map.py: the coarse-grained map of a sand pile at rest (issue 34, item 3).

Shared by pile_record.py (writes a record's map.h5) and pile_stats.py (pools
the maps of a group). docs/dem.md "The density and stress maps".

    cg_args(run_dir) -> [ekmcompare cg options]
        the grid of a run's map: --axes x,z --types 1 --stress c_sa --kernel
        gauss --width d --bins NX,NZ --range 0:NZ*2d --steps S:S, NX =
        round(lx / 2d) (2 d bins over the box's period along x, symmetric
        about its middle, the source's centre), NZ = floor(lz / 2d) (2 d rows
        from the plate's top z = 0 up to the box's top), S the last step of
        the run's atoms.dump (the pile at rest), --dt dt (LIGGGHTS writes no
        ITEM: TIME); d, lx, lz, dt of vars.txt
    write_map(cg_h5, out_h5, d)
        the record's map.h5 from that `ekmcompare cg` output: x, z [m] and
        phi [1], cxx, czz, cxz [Pa] ([nz][nx], x fastest; the contact stress
        of the per-atom c_sa, negative in compression, as ekmcompare writes
        it), gzip-compressed, each with units; the cg output's attributes
        that say how it was made
    read_map(path) -> {x, z, phi, cxx, czz, cxz, attrs}, checked
    analyse(maps, paths, opts) -> (stats dict, arrays dict)
        the group's statistics (below; opts: band, flank_lo, flank_hi,
        surface, floor in units of d)

Errors raise MapError(code, message): 2 bad input (one line naming the
file and what was expected), 3 a file missing or unreadable.

The statistics of a group of R maps (R >= 1; the SEs over runs need 2):
  mean map    phi, cxx, czz, cxz: the mean over the runs per cell, and its SE
              sd / sqrt(R)
  surface     from the mean phi: phi_b = the median of phi over the cells
              with phi > 0.1 max phi; h(x) = the height at which phi first
              falls below phi_b / 2 going up a column (linear between cell
              centres; the grid's top if it never does, 0 if the bottom
              cell is below)
  mask        a cell counts when its bottom is at least `floor` d above the
              plate (z - dz/2 >= floor d: the layering at the plate and the
              open lower end of the grid) and its top at least `surface` d
              below h(x) (z + dz/2 <= h(x) - surface d: the loose surface
              layer and the kernel's reach)
  bands       s = |x - c|, c the grid's middle: the apex band s < band d,
              the flank bands flank_lo d <= s < flank_hi d on each side
  deficit     per row z_j of the mask holding apex cells and flank cells
              on both sides: D_j = phi_apex(z_j) - (phi_left(z_j) +
              phi_right(z_j)) / 2, each the mean over that band's masked
              cells of the row; per run D_r = the mean of D_j over the rows
              (the same rows and cells for every run: the mask of the mean
              map); the value is the mean of D_r (equal to the statistic of
              the mean map), negative when the pile is less dense under
              its apex than under its flanks at the same heights. se_runs =
              sd(D_r) / sqrt(R); the map's own noise: per run the SE of its
              row mean, sd_j(D_rj) / sqrt(rows) (rows 2 d apart, a kernel of
              sd d: nearly independent; a real trend with height counts as
              noise here), se_map = sqrt(sum_r se_map_r^2) / R, the SE the
              group would have if the maps' own noise were all; left and
              right: the same against each flank alone
  directions  sigma = -c (compression positive); theta(x, z) the angle of
              the major principal axis of (sigma_xx, sigma_zz, sigma_xz)
              from the vertical, tan 2 theta = 2 sigma_xz / (sigma_zz -
              sigma_xx), in (-90, 90] deg, > 0 when its upper end leans
              towards +x (NaN outside the pile, phi < phi_b / 2, or where
              sigma_xx + sigma_zz <= 0); lean = -theta sign(x - c), > 0 when
              the upper end leans towards the centre
  arch        K_apex = sum sigma_xx / sum sigma_zz over the apex band's
              masked cells, per run and of the mean map, with its SE over
              runs: the major principal stress under the apex is horizontal
              when K_apex > 1 (by symmetry it is horizontal or vertical at
              the centre): "arches" is true when K_apex - 1 > 2 SE, false
              when 1 - K_apex > 2 SE, null otherwise (or without an SE); the
              mean |theta| over the apex band's masked cells; the mean lean
              over the flank bands' masked cells (per run, SE). An inward
              lean on the flanks alone is no arch: the free surface makes
              the major axis parallel to the slope near it in any pile.
"""
import math
import os

import numpy as np

FORMAT = "ekmbench sand-pile map 1"
FIELDS = (("phi", "1"), ("cxx", "Pa"), ("czz", "Pa"), ("cxz", "Pa"))
h5py = None  # imported on first use (the callers check that it exists)


class MapError(Exception):
    def __init__(self, code, msg):
        super().__init__(msg)
        self.code = code


def _h5():
    global h5py
    if h5py is None:
        import h5py as h
        h5py = h
    return h5py


def _str(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def read_vars(run):
    import pile_dump  # beside this file, as pile_record.py imports this one
    path = os.path.join(run, "vars.txt")
    try:
        out = pile_dump.read_vars(run)
    except pile_dump.DumpError as e:
        raise MapError(e.code, str(e)) from None
    for k in ("d", "lx", "lz", "dt"):
        if not (out.get(k, 0) > 0):
            raise MapError(2, "%s: expected %s > 0 (the deck's grain diameter, box and time step)" % (path, k))
    return out


def last_step(dump):
    if not os.path.isfile(dump):
        raise MapError(3, "%s: no such file" % dump)
    step = None
    with open(dump) as f:
        for line in f:
            if line.startswith("ITEM: TIMESTEP"):
                try:
                    step = int(next(f))
                except (StopIteration, ValueError):
                    raise MapError(2, "%s: ITEM: TIMESTEP without a step" % dump) from None
    if step is None:
        raise MapError(2, "%s: expected a LAMMPS/LIGGGHTS dump, found no ITEM: TIMESTEP" % dump)
    return step


def cg_args(run):
    v = read_vars(run)
    d = v["d"]
    nx = max(1, int(round(v["lx"] / (2 * d))))
    nz = int(math.floor(v["lz"] / (2 * d) + 1e-9))
    if nz < 1:
        raise MapError(2, "%s: lz = %g m holds no row of 2 d" % (os.path.join(run, "vars.txt"), v["lz"]))
    s = last_step(os.path.join(run, "atoms.dump"))
    return ["--axes", "x,z", "--types", "1", "--stress", "c_sa", "--kernel", "gauss", "--width", "%.9g" % d,
            "--bins", "%d,%d" % (nx, nz), "--range", "0:%.9g" % (nz * 2 * d), "--steps", "%d:%d" % (s, s),
            "--dt", "%.9g" % v["dt"]]


KEEP_ATTRS = ("inputs", "kernel", "width", "dx", "dz", "x_lo", "x_hi", "lo", "hi", "averaged_over",
              "averaged_length", "atom_types", "stress", "window", "snapshots_used", "code_version")


def write_map(cg_path, out_path, d):
    """map.h5 from an `ekmcompare cg --axes x,z` output of one snapshot."""
    h5 = _h5()
    try:
        f = h5.File(cg_path, "r")
    except OSError as e:
        raise MapError(2, "%s: expected the HDF5 output of ekmcompare cg --axes x,z (%s)" % (cg_path, e)) from None
    with f:
        if _str(f.attrs.get("axis", "")) != "x,z":
            raise MapError(2, "%s: expected an ekmcompare cg --axes x,z output (axis x,z)" % cg_path)
        for name, _ in FIELDS:
            if name not in f:
                raise MapError(2, "%s: no dataset %s (expected cg --stress)" % (cg_path, name))
        data = {name: np.asarray(f[name][...], dtype=float) for name, _ in FIELDS}
        x = np.asarray(f["x"][...], dtype=float)
        z = np.asarray(f["z"][...], dtype=float)
        attrs = {k: f.attrs[k] for k in KEEP_ATTRS if k in f.attrs}
    for name, a in data.items():
        if a.shape != (1, z.size, x.size):
            raise MapError(2, "%s: %s: expected one window [1][%d][%d], got %s" % (cg_path, name, z.size, x.size,
                                                                                  a.shape))
        if not np.isfinite(a).all():
            raise MapError(2, "%s: %s: expected finite values" % (cg_path, name))
    tmp = os.path.join(os.path.dirname(os.path.abspath(out_path)), ".%s.tmp%d" % (os.path.basename(out_path),
                                                                                 os.getpid()))
    try:
        with h5.File(tmp, "w") as g:
            for name, arr, units in (("x", x, "m"), ("z", z, "m")):
                ds = g.create_dataset(name, data=arr)
                ds.attrs["units"] = np.bytes_(units)
            for name, units in FIELDS:
                ds = g.create_dataset(name, data=data[name][0], compression="gzip", compression_opts=6,
                                      shuffle=True)
                ds.attrs["units"] = np.bytes_(units)
            g.attrs["format"] = np.bytes_(FORMAT)
            g.attrs["d"] = float(d)
            g.attrs["centre"] = float(0.5 * (x[0] + x[-1]))
            g.attrs["made"] = np.bytes_("ekmcompare cg --axes x,z --types 1 --stress c_sa of the run's last "
                                        "snapshot (scripts/dem/pile_record.sh, pile_map.py cg_args)")
            g.attrs["fields"] = np.bytes_("phi: solid fraction of the pile grains (type 1); cxx czz cxz: their "
                                          "contact stress [Pa], per-atom c_sa, negative in compression; [nz][nx], "
                                          "x fastest")
            for k, v in attrs.items():
                g.attrs["cg_" + k] = v
        os.replace(tmp, out_path)
    except OSError as e:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise MapError(3, "%s: cannot write (%s)" % (out_path, e.strerror or e)) from None


def read_map(path):
    if not os.path.exists(path):
        raise MapError(3, "%s: no such file" % path)
    h5 = _h5()
    try:
        f = h5.File(path, "r")
    except OSError as e:
        raise MapError(2, "%s: expected a record's map.h5 (HDF5: %s)" % (path, e)) from None
    with f:
        if _str(f.attrs.get("format", "")) != FORMAT:
            raise MapError(2, "%s: expected the attribute format \"%s\"" % (path, FORMAT))
        out = {"attrs": {k: f.attrs[k] for k in f.attrs}}
        for name in ("x", "z") + tuple(n for n, _ in FIELDS):
            if name not in f:
                raise MapError(2, "%s: no dataset %s (expected a record's map.h5)" % (path, name))
            out[name] = np.asarray(f[name][...], dtype=float)
            units = dict(FIELDS + (("x", "m"), ("z", "m")))[name]
            if _str(f[name].attrs.get("units", "")) != units:
                raise MapError(2, "%s: %s: expected units %s" % (path, name, units))
        for a in ("d", "centre"):
            if a not in f.attrs:
                raise MapError(2, "%s: no attribute %s (expected a record's map.h5)" % (path, a))
    x, z = out["x"], out["z"]
    if x.ndim != 1 or z.ndim != 1 or x.size < 3 or z.size < 2:
        raise MapError(2, "%s: x, z: expected cell centres, at least 3 and 2" % path)
    for name, _ in FIELDS:
        if out[name].shape != (z.size, x.size):
            raise MapError(2, "%s: %s: expected [%d][%d] (z, x), got %s" % (path, name, z.size, x.size,
                                                                            out[name].shape))
        if not np.isfinite(out[name]).all():
            raise MapError(2, "%s: %s: expected finite values" % (path, name))
    if out["phi"].min() < 0 or out["phi"].max() > 1:
        raise MapError(2, "%s: phi: expected values in [0, 1], got %g .. %g" % (path, out["phi"].min(),
                                                                               out["phi"].max()))
    out["d"] = float(out["attrs"]["d"])
    out["centre"] = float(out["attrs"]["centre"])
    return out


def same_grid(maps, paths):
    m0 = maps[0]
    for m, p in zip(maps, paths):
        if (m["x"].size != m0["x"].size or m["z"].size != m0["z"].size
                or not np.allclose(m["x"], m0["x"], rtol=0, atol=1e-9 * m0["d"])
                or not np.allclose(m["z"], m0["z"], rtol=0, atol=1e-9 * m0["d"])
                or abs(m["d"] - m0["d"]) > 1e-9 * m0["d"]):
            raise MapError(2, "%s: a grid of %d x %d cells (x %g .. %g, z %g .. %g m, d %g), expected that of %s "
                           "(%d x %d)" % (p, m["x"].size, m["z"].size, m["x"][0], m["x"][-1], m["z"][0], m["z"][-1],
                                          m["d"], paths[0], m0["x"].size, m0["z"].size))


def surface(phim, z):
    inside = phim > 0.1 * phim.max()
    if not inside.any():
        return np.zeros(phim.shape[1]), 0.0
    phib = float(np.median(phim[inside]))
    half = 0.5 * phib
    h = np.empty(phim.shape[1])
    for i in range(phim.shape[1]):
        col = phim[:, i]
        below = np.nonzero(col < half)[0]
        if below.size == 0:
            h[i] = z[-1] + 0.5 * (z[-1] - z[-2])
        elif below[0] == 0:
            h[i] = 0.0
        else:
            j = below[0]
            h[i] = z[j - 1] + (col[j - 1] - half) / (col[j - 1] - col[j]) * (z[j] - z[j - 1])
    return h, phib


def principal(sxx, szz, sxz):
    """Angle [deg] of the major principal axis from the vertical (compression positive)."""
    th = 0.5 * np.degrees(np.arctan2(2 * sxz, szz - sxx))
    return np.where(th <= -90.0, th + 180.0, th)


def _se(v):
    v = np.asarray(v, dtype=float)
    return float(np.std(v, ddof=1) / math.sqrt(v.size)) if v.size >= 2 else None


def analyse(maps, paths, opts):
    """Statistics of a group's maps (docs above); opts: band, flank_lo, flank_hi, surface, floor [d]."""
    same_grid(maps, paths)
    m0 = maps[0]
    x, z, d, c = m0["x"], m0["z"], m0["d"], m0["centre"]
    R = len(maps)
    dz = float(z[1] - z[0])
    phi = np.stack([m["phi"] for m in maps])
    sig = {k: -np.stack([m["c" + k] for m in maps]) for k in ("xx", "zz", "xz")}
    phim = phi.mean(axis=0)
    sm = {k: v.mean(axis=0) for k, v in sig.items()}
    h, phib = surface(phim, z)
    Z = z[:, None] * np.ones((1, x.size))
    mask = (Z - 0.5 * dz >= opts["floor"] * d - 1e-9 * d) & (Z + 0.5 * dz <= h[None, :] - opts["surface"] * d)
    s = np.abs(x - c)
    apex = s < opts["band"] * d
    flank = (s >= opts["flank_lo"] * d) & (s < opts["flank_hi"] * d)
    left, right = flank & (x < c), flank & (x > c)
    rows = [j for j in range(z.size) if (mask[j] & apex).any() and (mask[j] & left).any()
            and (mask[j] & right).any()]
    out = {"runs": R, "d": d, "centre": c, "dx": float(x[1] - x[0]), "dz": dz, "cells": [int(z.size), int(x.size)],
           "phi_bulk": phib, "options_d": dict(opts),
           "surface_height_max": float(h.max())}
    arrays = {"x": x, "z": z, "h": h, "mask": mask.astype(float), "phi": phim,
              "phi_se": phi.std(axis=0, ddof=1) / math.sqrt(R) if R >= 2 else np.full(phim.shape, np.nan)}
    for k in ("xx", "zz", "xz"):
        arrays["s" + k] = sm[k]
        arrays["s" + k + "_se"] = (sig[k].std(axis=0, ddof=1) / math.sqrt(R) if R >= 2
                                   else np.full(phim.shape, np.nan))
    with np.errstate(invalid="ignore"):
        theta = principal(sm["xx"], sm["zz"], sm["xz"])
        theta = np.where((phim >= 0.5 * phib) & (sm["xx"] + sm["zz"] > 0), theta, np.nan)
    lean = -theta * np.sign(x - c)[None, :]
    arrays["theta"], arrays["lean"] = theta, lean
    # the density under the apex against the flanks
    if not rows:
        out["phi_apex_minus_flanks"] = None
        out["phi_apex_minus_flanks_missing"] = ("no row of the mask holds apex and flank cells on both sides "
                                                "(surface height max %.3g m): a pile too low for these bands"
                                                % h.max())
    else:
        def band_mean(P, sel, j):
            return P[:, j, mask[j] & sel].mean(axis=1)
        C = np.stack([band_mean(phi, apex, j) for j in rows], axis=1)     # [R][rows]
        L = np.stack([band_mean(phi, left, j) for j in rows], axis=1)
        Rt = np.stack([band_mean(phi, right, j) for j in rows], axis=1)
        Dj = C - 0.5 * (L + Rt)
        Dr = Dj.mean(axis=1)
        n = len(rows)
        se_map_r = Dj.std(axis=1, ddof=1) / math.sqrt(n) if n >= 2 else np.full(R, np.nan)
        val = float(Dr.mean())
        se = _se(Dr)
        flank_phi = float(0.5 * (L + Rt).mean())
        dl, dr = (C - L).mean(axis=1), (C - Rt).mean(axis=1)
        out["phi_apex_minus_flanks"] = {
            "value": val, "se_runs": se, "z_runs": val / se if se else None,
            "se_map": float(math.sqrt(np.sum(se_map_r ** 2)) / R) if n >= 2 else None,
            "relative": val / flank_phi, "phi_flanks": flank_phi, "phi_apex": float(C.mean()),
            "less_dense_under_apex_at_3se": bool(se is not None and val + 3 * se < 0),
            "per_run": [float(v) for v in Dr], "se_map_per_run": [float(v) for v in se_map_r],
            "left": {"value": float(dl.mean()), "se_runs": _se(dl)},
            "right": {"value": float(dr.mean()), "se_runs": _se(dr)},
            "rows": [{"z": float(z[j]), "value": float(Dj[:, k].mean()), "se_runs": _se(Dj[:, k]),
                      "apex_cells": int((mask[j] & apex).sum()), "flank_cells": int((mask[j] & flank).sum())}
                     for k, j in enumerate(rows)]}
    # the principal directions and the arch
    ac = mask & apex[None, :]
    fc = mask & flank[None, :]
    arch = {}
    if ac.any():
        szz_r = sig["zz"][:, ac].sum(axis=1)
        sxx_r = sig["xx"][:, ac].sum(axis=1)
        if np.all(szz_r > 0):
            Kr = sxx_r / szz_r
            K = float(sm["xx"][ac].sum() / sm["zz"][ac].sum())
            se = _se(Kr)
            arch["K_apex"] = {"value": K, "se_runs": se, "per_run": [float(v) for v in Kr]}
            arch["arches"] = (None if not se else True if K - 1 > 2 * se else False if 1 - K > 2 * se else None)
        else:
            arch["K_apex"] = None
            arch["K_apex_missing"] = "sum of sigma_zz over the apex band <= 0 in some run (no contact stress?)"
            arch["arches"] = None
        th = theta[ac]
        arch["theta_apex_deg"] = float(np.nanmean(np.abs(th))) if np.isfinite(th).any() else None
    else:
        arch["K_apex"] = None
        arch["K_apex_missing"] = "no masked cell in the apex band"
        arch["arches"] = None
    if fc.any():
        with np.errstate(invalid="ignore"):
            per = []
            for r in range(R):
                t = principal(sig["xx"][r], sig["zz"][r], sig["xz"][r])
                ok = fc & (sig["xx"][r] + sig["zz"][r] > 0)
                per.append(float(np.mean((-t * np.sign(x - c)[None, :])[ok])) if ok.any() else np.nan)
        lf = lean[fc]
        arch["lean_flanks_deg"] = {"value": float(np.nanmean(lf)) if np.isfinite(lf).any() else None,
                                   "se_runs": _se(per) if np.isfinite(per).all() else None, "per_run": per}
    out["arch"] = arch
    return out, arrays
