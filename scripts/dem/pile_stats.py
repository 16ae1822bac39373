#!/usr/bin/python3
"""pile_stats.py: the dip statistics of sand-pile base-pressure ensembles.

    scripts/dem/pile_stats.py [options] -o STATS.json NAME=BASE.h5 ...

Each NAME=BASE.h5 is one group (an engine, a source, a contact law), BASE.h5
the output of `ekmcompare base --last 1 --centre XC` over the group's runs
(one dump per run, an independent pile): p_base_runs [runs][bins] on bins
of width dx symmetric about the source's centre XC (docs/dem.md "Sand pile:
the observable"). Per group:

  profile   P(x), the mean of the runs' profiles on bins of --merge K base
            bins (K odd if the grid has an odd number of bins, even if
            even, so that the central bin stays centred on XC; bins with no
            floor grain, beyond the plate, are NaN and dropped), folded:
            F(s) = (P(XC + s) + P(XC - s)) / 2
  dip       D = 1 - F(0) / max_s F(s): the dip depth (0 without a dip,
            < 0 impossible on the folded profile: the max includes s = 0)
  halves    D_left, D_right: the same from each half of P unfolded (P(0)
            over the largest P of that half); (D_left + D_right)/2 and
            |D_left - D_right|/2, the second estimate of D and its spread
  maxima    s_max (of F), x_left, x_right (of each half of P), distances
            from XC [m]
  bootstrap over the runs (--boot B resamples with replacement, --seed):
            SE = sd of the resampled statistic times sqrt(R/(R-1)) (R
            runs: resampling gives the variance of their mean times
            (R-1)/R); the basic (reverse percentile) interval
            [2 T - q_hi, 2 T - q_lo] at --level, its half-widths scaled by
            the same factor, which removes to first order the upward bias
            of a maximum over noisy bins; the bias estimate mean(T*) - T
  design    sigma_run = SE(D) sqrt(R), the per-run noise of D; the runs
            needed to resolve a dip depth --target at 3 SE: (3 sigma_run /
            target)^2
  fit       the lower-noise estimator (issue 34: D on 10 d bins needs about
            41 runs per group): on the base bins (before merging), the
            folded profile F(s) for s <= --fit-window (default 0.06 m, 30 d
            of the reference grains), a least-squares quadratic q(s) = a +
            b s + c s^2 (each folded bin weighted by the base bins it
            holds); D_fit = 1 - q(0) / max q over [0, window] (the fitted
            dip depth, >= 0) and D_ref = 1 - q(0) / q(--fit-ref) (default
            0.02 m, 10 d: signed, < 0 where p falls from the centre); each
            with the bootstrap SE and interval as above, its value per run
            and their sd (sd_runs), the same from each half of each run
            alone (sd_halves = rms of (left - right)/2) and the runs for
            --target at 3 SE from each of the three. Its model bias: 0 on a
            linear wedge profile, 0.245 for a quadratic dip of depth 0.25,
            and 0.054 on a profile flat over s < 25 d and falling beyond
            (tests/dem/pile_stats_test.py)
  local weight (unless --no-dumps) from the dumps the HDF5 names (inputs),
            their last frame: the surface height h(x) of each run (the
            highest z + radius of the pile grains, type 1, on the plate:
            z > 0 and |x - xmid| < lp/2, lp of the run's vars.txt beside
            the dump, in each base bin), the bulk density rho_b = M / (L_y sum
            h dx) (M the pile's mass), W(x) = rho_b g h(x), and the ratio
            P(x) / W(x) with its bootstrap SE; the floor grains per base bin
            (aligned bins hold the same number; p is renormalised by
            n_mean / n_bin otherwise, and the largest |n_bin/n_mean - 1| is
            reported). In a file assembled from run records
            (scripts/dem/pile_record.py group) the same numbers per run are
            its h_runs, floor_grains_runs and pile_mass_runs (computed from
            each dump when it was recorded); when some record has none
            (recovered from an earlier group file) the group has no local
            weight and says so (local_weight_missing)
  map       (a file assembled from run records, whose inputs name the
            records) from every record's map.h5 (pile_map.py: the pile at
            rest coarse-grained on 2 d cells, phi and the contact stress):
            the mean map and its SE over runs; phi under the apex minus phi
            under the flanks at matched heights (--map-band, --map-flanks,
            --map-surface, --map-floor, in grain diameters d) with its SE
            over runs and the maps' own noise; the major principal stress's
            angle from the vertical in the mean map, K_apex = sigma_xx /
            sigma_zz under the apex and whether it arches (K_apex > 1 by 2
            SE); definitions in pile_map.py and docs/dem.md "The density and
            stress maps". When some record has no map.h5 (recorded before
            the maps, or recovered) the group says so (map_missing)
--compare A,B (repeatable): D_A - D_B with its bootstrap SE (independent
groups) and a two-sided permutation test over the pooled runs (--perm N
relabellings): p = (1 + #{|T*| >= |T|}) / (1 + N), and the same for D_fit;
the two groups must share the grid.

Outputs (each written to a temporary name and renamed): -o STATS.json; --h5
PROFILES.h5 (a group per NAME: s, F and its interval; x, P and its
interval; W, ratio), --maps-h5 MAPS.h5 (a group per NAME with a map: x, z,
the mean maps phi, sxx, szz, sxz (compression positive) and their SEs,
theta and lean [deg], the surface h and the mask) and --csv PROFILES.csv (the same, one row per group and
merged bin). Exit status (docs/exit-codes.md): 0 ok; 1 usage; 2 bad input
(one line naming the file and what was expected: not an ekmcompare base
HDF5, a missing dataset or attribute, fewer than 2 runs, a group without a
bin beyond the centre, grids that differ in a comparison, a dump without
the columns needed); 3 a file cannot be read or written.
"""
import argparse
import json
import math
import os
import sys
import warnings

import numpy as np

import pile_dump  # scripts/dem: the dump reader shared with pile_summary.py

h5py = None  # imported in main (a clear message without it)
PROG = "pile_stats"


class Fail(Exception):
    def __init__(self, code, msg):
        super().__init__(msg)
        self.code = code


def die(code, msg):
    raise Fail(code, msg)


# ---------------------------------------------------------------- inputs
def read_base(path):
    """(x, dx, centre, y_period, runs [R][n], inputs, surface) of an ekmcompare base HDF5;
    surface: (h_runs, floor_grains_runs, pile_mass_runs) of a file assembled from
    run records (pile_record.py group) when every record had its surface, the
    string "records" when some had none, None for ekmcompare's own output."""
    if not os.path.exists(path):
        die(3, "%s: no such file" % path)
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        die(2, "%s: expected an HDF5 file of ekmcompare base (%s)" % (path, e))
    with f:
        for name in ("x", "p_base_runs"):
            if name not in f:
                die(2, "%s: no dataset %s (expected the output of ekmcompare base)" % (path, name))
        for a in ("dx", "centre", "y_period"):
            if a not in f.attrs:
                die(2, "%s: no attribute %s (expected the output of ekmcompare base)" % (path, a))
        x = np.asarray(f["x"][...], dtype=float)
        runs = np.asarray(f["p_base_runs"][...], dtype=float)
        dx = float(f.attrs["dx"])
        centre = float(f.attrs["centre"])
        ly = float(f.attrs["y_period"])
        inputs = f.attrs.get("inputs", "")
        if isinstance(inputs, bytes):
            inputs = inputs.decode()
        surface = None
        if "h_runs" in f:
            for name in ("floor_grains_runs", "pile_mass_runs"):
                if name not in f:
                    die(2, "%s: h_runs without %s (expected the output of pile_record.py group)" % (path, name))
            surface = tuple(np.asarray(f[k][...], dtype=float) for k in ("h_runs", "floor_grains_runs", "pile_mass_runs"))
            if surface[0].shape != runs.shape or surface[1].shape != runs.shape or surface[2].shape != runs.shape[:1]:
                die(2, "%s: h_runs, floor_grains_runs: expected [%d runs][%d bins] as p_base_runs, pile_mass_runs "
                    "[%d]" % (path, runs.shape[0], x.size, runs.shape[0]))
        elif "assembled" in f.attrs:
            surface = "records"
    if runs.ndim != 2 or runs.shape[1] != x.size:
        die(2, "%s: p_base_runs: expected [runs][%d bins], got shape %s" % (path, x.size, runs.shape))
    if runs.shape[0] < 2:
        die(2, "%s: p_base_runs: expected at least 2 runs (independent piles) for a bootstrap, got %d"
            % (path, runs.shape[0]))
    if not (dx > 0 and ly > 0):
        die(2, "%s: expected dx > 0 and y_period > 0, got %g and %g" % (path, dx, ly))
    return x, dx, centre, ly, runs, [s for s in inputs.split("\n") if s], surface


def last_frame(path):
    """(box x bounds, box y period, {column: array}) of a dump's last frame."""
    if not os.path.exists(path):
        die(3, "%s: no such file (named by the base HDF5's inputs; or give --no-dumps)" % path)
    try:
        fr = pile_dump.last_frame(path)
    except pile_dump.DumpError as e:
        die(e.code, str(e))
    for c in ("type", "x", "z", "radius", "mass"):
        if c not in fr.cols:
            die(2, "%s: ITEM: ATOMS has no column %s (docs/dem.md \"Sand pile\")" % (path, c))
    a = np.array(fr.rows, dtype=float).reshape(len(fr.rows), len(fr.cols))
    return fr.bx, fr.ly, {c: a[:, i] for i, c in enumerate(fr.cols)}


def heights(dump, x, dx):
    """(h per base bin, floor grains per base bin, pile mass) of a dump's last frame."""
    bx, ly, col = last_frame(dump)
    lo = x[0] - 0.5 * dx
    L = bx[1] - bx[0]
    xs = bx[0] + np.mod(col["x"] - bx[0], L)
    k = np.floor((xs - lo) / dx).astype(int)
    inside = (k >= 0) & (k < x.size)
    # the pile: grains on the plate (z > 0, |x - xmid| < lp/2, lp from the
    # run's vars.txt beside the dump; without it the whole box)
    half = pile_dump.plate_half_width(os.path.dirname(os.path.abspath(dump)), L)
    onp = (col["type"] == 1) & pile_dump.on_plate(col["x"], col["z"], 0.5 * (bx[0] + bx[1]), half)
    pile = onp & inside
    floor = (col["type"] == 2) & inside
    h = np.zeros(x.size)
    np.maximum.at(h, k[pile], col["z"][pile] + col["radius"][pile])
    nfl = np.bincount(k[floor], minlength=x.size).astype(float)
    mass = float(col["mass"][onp].sum())
    return h, nfl, mass, ly


# ------------------------------------------------------------- statistics
def merge_plan(n, K, path):
    """Index lists of the merged bins, the central one centred; None if K does not fit."""
    if K < 1 or (n % 2) != (K % 2):
        die(1, "--merge %d: expected a number of base bins of the parity of the grid's %d bins "
            "(%s), so that the central bin stays centred" % (K, n, "odd" if n % 2 else "even"))
    first = n // 2 - K // 2  # the central merged bin: first .. first + K - 1
    groups = []
    # the merged bins from the leftmost that fits to the rightmost
    lo = first
    while lo - K >= 0:
        lo -= K
    start = lo
    while start + K <= n:
        groups.append(list(range(start, start + K)))
        start += K
    centre_groups = [i for i, grp in enumerate(groups) if grp[0] == first]
    if not centre_groups:
        die(2, "%s: %d bins cannot be merged by %d about the centre" % (path, n, K))
    return groups, centre_groups[0]


def merged(prof, groups):
    """prof [..., n] -> [..., m]: mean of each group's bins (NaN if any is NaN)."""
    return np.stack([prof[..., grp].mean(axis=-1) for grp in groups], axis=-1)


def dip_stats(P, ic, sx):
    """Statistics of mean profiles P [..., m] (merged, central bin ic; sx distance of each bin)."""
    m = P.shape[-1]
    nside = min(ic, m - 1 - ic)
    right = P[..., ic:ic + nside + 1]
    left = P[..., ic - nside:ic + 1][..., ::-1]
    F = 0.5 * (right + left)
    Fm = np.where(np.isfinite(F), F, -np.inf)
    D = 1.0 - F[..., 0] / Fm.max(axis=-1)
    s_max = sx[ic:ic + nside + 1][Fm.argmax(axis=-1)]
    out = {"D": D, "s_max": s_max, "F": F}
    for side, H in (("left", left), ("right", right)):
        Hm = np.where(np.isfinite(H), H, -np.inf)
        out["D_" + side] = 1.0 - H[..., 0] / Hm.max(axis=-1)
        out["x_" + side] = sx[ic:ic + nside + 1][Hm.argmax(axis=-1)]
    out["D_halves"] = 0.5 * (out["D_left"] + out["D_right"])
    out["D_halves_spread"] = 0.5 * np.abs(out["D_left"] - out["D_right"])
    return out


def fold_base(x, centre, dx, path=""):
    """(j, m, s, w) of the fold of a base grid symmetric about centre: bin j
    (x >= centre) pairs with m = n - 1 - j, at s = x_j - centre, weight w (1
    for the central bin, its own mirror, else 2: two bins)."""
    n = x.size
    if not np.allclose(x + x[::-1], 2 * centre, rtol=0, atol=1e-6 * dx):
        die(2, "%s: the base grid is not symmetric about its centre %g m (ekmcompare base --centre)" % (path, centre))
    j = np.arange(n // 2, n)
    m = n - 1 - j
    return j, m, x[j] - centre, np.where(j == m, 1.0, 2.0)


def fit_dip(P, fold, window, ref):
    """The dip of a quadratic fitted to the folded profile near the centre.

    P [..., n] profiles on the base grid; fold = fold_base(...). F(s) = (P(c + s)
    + P(c - s))/2 on the base bins with s <= window, least squares (each bin
    weighted by the base bins it holds) of q(s) = a + b s + c s^2; returns
    (D_fit, D_ref, q at the window's grid): D_fit = 1 - q(0) / max q over
    [0, window] (the fitted dip depth, >= 0), D_ref = 1 - q(0) / q(ref) (the
    fitted rise from the centre to s = ref: signed, < 0 where p falls from
    the centre; D_ref <= D_fit)."""
    j, m, s, w = fold
    use = s <= window + 1e-9 * max(window, 1e-30)
    F = 0.5 * (P[..., j[use]] + P[..., m[use]])
    X = np.stack([np.ones(use.sum()), s[use], s[use] ** 2], axis=1)
    sw = np.sqrt(w[use])
    A = np.linalg.pinv(X * sw[:, None]) * sw[None, :]   # beta = A @ F
    beta = F @ A.T                                       # [..., 3]
    grid = np.linspace(0.0, s[use].max(), 301)
    V = np.stack([np.ones_like(grid), grid, grid ** 2], axis=1)
    q = beta @ V.T
    q0 = beta[..., 0]
    qref = beta[..., 0] + beta[..., 1] * ref + beta[..., 2] * ref ** 2
    return 1.0 - q0 / q.max(axis=-1), 1.0 - q0 / qref, q


def interval(t, boot, level, runs):
    """Basic bootstrap interval, its half-widths scaled by sqrt(R/(R-1)):
    resampling R runs gives the variance of their mean times (R-1)/R."""
    k = math.sqrt(runs / (runs - 1))
    lo, hi = np.quantile(boot, [0.5 * (1 - level), 0.5 * (1 + level)], axis=0)
    return t - k * (hi - t), t + k * (t - lo)


def boot_indices(rng, R, B):
    return rng.integers(0, R, size=(B, R))


MAPS = {}  # NAME -> arrays of the mean map (--maps-h5)


def group_map(name, path, inputs, args):
    """The map statistics of a group assembled from run records, or why there are none."""
    try:
        with h5py.File(path, "r") as f:
            assembled = "assembled" in f.attrs
    except OSError as e:
        die(2, "%s: expected an HDF5 file of ekmcompare base (%s)" % (path, e))
    if not assembled:
        return {"map_missing": "not assembled from run records (pile_record.py group): the maps are in the records"}
    paths = [os.path.join(i, "map.h5") for i in inputs]
    have = [p for p in paths if os.path.exists(p)]
    if not have:
        return {"map_missing": "none of the %d records has a map.h5 (recorded before the maps, or recovered from "
                               "group files): no density or stress map" % len(paths)}
    # a record without a map was recorded before the maps (or recovered from
    # a group file): nothing about its pile, so the records that have one
    # are a fair subset
    partial = None
    if len(have) < len(paths):
        partial = ("over the %d of %d records that have a map.h5 (the others recorded before the maps, or "
                   "recovered from group files)" % (len(have), len(paths)))
    import pile_map
    try:
        maps = [pile_map.read_map(p) for p in have]
        st, arrays = pile_map.analyse(maps, have, {"band": args.map_band, "flank_lo": args.map_flanks[0],
                                                    "flank_hi": args.map_flanks[1], "surface": args.map_surface,
                                                    "floor": args.map_floor})
    except pile_map.MapError as e:
        die(e.code, str(e))
    MAPS[name] = arrays
    st["files"] = have
    st["runs"] = len(have)
    if partial:
        st["partial"] = partial
    return {"map": st}


def summarise(name, path, args, rng):
    x, dx, centre, ly, runs, inputs, surface = read_base(path)
    R, n = runs.shape
    info = {"file": path, "runs": R, "bins": n, "dx": dx, "centre": centre, "y_period": ly}
    W = None
    hs = None
    if args.no_dumps:
        pass
    elif isinstance(surface, tuple):  # from the run records
        hs, ns, ms = surface
    elif surface == "records":
        info["local_weight_missing"] = ("assembled from run records of which some have no surface (recovered "
                                        "from group files): no local weight, no floor-count renormalisation")
    else:
        if len(inputs) != R:
            die(2, "%s: inputs names %d dumps for %d runs (or give --no-dumps)" % (path, len(inputs), R))
        hs, ns, ms = [], [], []
        for d in inputs:
            h, nfl, mass, ly_d = heights(d, x, dx)
            if abs(ly_d - ly) > 1e-9 * ly:
                die(2, "%s: box y period %g m, expected the base HDF5's %g m" % (d, ly_d, ly))
            hs.append(h)
            ns.append(nfl)
            ms.append(mass)
        hs, ns, ms = np.array(hs), np.array(ns), np.array(ms)
    if hs is not None:
        plate = ns.sum(axis=0) > 0
        nmean = ns[:, plate].mean()
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.where(ns > 0, nmean / ns, np.nan)
        info["floor_grains_per_bin"] = nmean
        info["floor_count_max_deviation"] = float(np.nanmax(np.abs(1.0 / scale[:, plate] - 1.0)))
        runs = runs * np.where(np.isfinite(scale), scale, 1.0)
        rho_b = ms / (ly * (hs[:, plate].sum(axis=1) * dx))
        W = rho_b[:, None] * args.g * hs
        W[:, ~plate] = np.nan
        info["rho_b"] = {"mean": float(rho_b.mean()), "sd": float(rho_b.std(ddof=1))}
        info["height_max"] = {"mean": float(hs.max(axis=1).mean()), "sd": float(hs.max(axis=1).std(ddof=1))}
    # the fit estimator on the base bins (before merging)
    fold = fold_base(x, centre, dx, path)
    fj, fm, fs, _ = fold
    win = args.fit_window
    inwin = fs <= win * (1 + 1e-9)
    if inwin.sum() < 4 or fs[inwin].max() < win - dx:
        die(2, "%s: the fit window %g m holds %d folded bins (expected at least 4, reaching it)" % (path, win, inwin.sum()))
    if not np.isfinite(runs[:, np.concatenate([fj[inwin], fm[inwin]])]).all():
        die(2, "%s: the fit window (s <= %g m) reaches bins without floor grains" % (path, win))
    groups, ic = merge_plan(n, args.merge, path)
    xm = merged(x, groups)
    sx = np.abs(xm - centre)
    Pr = merged(runs, groups)
    finite = np.isfinite(Pr).all(axis=0)
    if finite.sum() < 2 or not finite[ic]:
        die(2, "%s: expected the central bin and one beyond it under the plate in every run" % path)
    P = Pr.mean(axis=0)
    st = dip_stats(P, ic, sx)
    idx = boot_indices(rng, R, args.boot)
    Pb = Pr[idx].mean(axis=1)
    sb = dip_stats(Pb, ic, sx)
    res = dict(info)
    res.update(group_map(name, path, inputs, args))
    corr = math.sqrt(R / (R - 1))  # the bootstrap SE of a mean of R runs is sqrt((R-1)/R) of sd/sqrt(R)
    res["merge"] = args.merge
    res["bin_width"] = args.merge * dx
    for key in ("D", "D_left", "D_right", "D_halves", "s_max", "x_left", "x_right"):
        t = float(st[key])
        b = sb[key]
        lo, hi = interval(t, b, args.level, R)
        res[key] = {"value": t, "se": float(b.std(ddof=1)) * corr, "ci": [float(lo), float(hi)],
                    "bias": float(b.mean() - t)}
    res["D_halves"]["spread"] = float(st["D_halves_spread"])
    # the fit estimator: on the mean profile, its bootstrap, and per run
    Dq, Dr, _ = fit_dip(runs.mean(axis=0), fold, win, args.fit_ref)
    Dqb, Drb, _ = fit_dip(runs[idx].mean(axis=1), fold, win, args.fit_ref)
    Dq1, Dr1, _ = fit_dip(runs, fold, win, args.fit_ref)
    # each half of each run alone (the other half replaced by its mirror):
    # (half_left - half_right)/2 has the variance of the folded estimate if
    # the halves' noise is independent (an asymmetric pile makes it larger)
    halves = []
    for src, dst in ((fm, fj), (fj, fm)):
        Ph = runs.copy()
        Ph[:, dst] = runs[:, src]
        halves.append(fit_dip(Ph, fold, win, args.fit_ref))
    for k, (key, t, b, per) in enumerate((("D_fit", Dq, Dqb, Dq1), ("D_ref", Dr, Drb, Dr1))):
        t = float(t)
        dh = 0.5 * (halves[0][k] - halves[1][k])
        sd_halves = float(np.sqrt(np.mean(dh ** 2)))
        lo, hi = interval(t, b, args.level, R)
        se = float(b.std(ddof=1)) * corr
        sd_runs = float(np.std(per, ddof=1))
        res[key] = {"value": t, "se": se, "ci": [float(lo), float(hi)], "bias": float(b.mean() - t),
                    "per_run": [float(v) for v in per], "sd_runs": sd_runs,
                    "per_run_left": [float(v) for v in halves[0][k]],
                    "per_run_right": [float(v) for v in halves[1][k]], "sd_halves": sd_halves,
                    "window": win, "ref": args.fit_ref if key == "D_ref" else None,
                    "design": {"sigma_run": se * math.sqrt(R),
                               "runs_for_target_at_3se": int(math.ceil((3 * se * math.sqrt(R) / args.target) ** 2)),
                               "runs_for_target_at_3se_from_sd_runs": int(math.ceil((3 * sd_runs / args.target) ** 2)),
                               "runs_for_target_at_3se_from_sd_halves": int(math.ceil((3 * sd_halves / args.target) ** 2))}}
    res["D_fit"]["resolved"] = bool(res["D_fit"]["ci"][0] > 0)
    res["D_ref"]["resolved"] = bool(res["D_ref"]["ci"][0] > 0)
    sig = res["D"]["se"] * math.sqrt(R)
    res["design"] = {"sigma_run": sig, "target": args.target,
                     "runs_for_target_at_3se": int(math.ceil((3 * sig / args.target) ** 2)),
                     "resolved_at_3se_now": 3 * res["D"]["se"]}
    res["resolved"] = bool(res["D"]["ci"][0] > 0)
    # profiles with their intervals
    Plo, Phi = interval(P, Pb, args.level, R)
    F = st["F"]
    Flo, Fhi = interval(F, sb["F"], args.level, R)
    prof = {"x": xm, "P": P, "P_lo": Plo, "P_hi": Phi, "P_se": Pb.std(axis=0, ddof=1) * corr}
    nside = F.shape[-1]
    fold_out = {"s": sx[ic:ic + nside], "F": F, "F_lo": Flo, "F_hi": Fhi, "F_se": sb["F"].std(axis=0, ddof=1) * corr}
    if W is not None:
        Wm = merged(W, groups)
        with np.errstate(divide="ignore", invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # bins beyond the pile: W = 0
            rb = Pr[idx].mean(axis=1) / Wm[idx].mean(axis=1)
            r = P / Wm.mean(axis=0)
            prof["ratio_se"] = np.nanstd(np.where(np.isfinite(rb), rb, np.nan), axis=0, ddof=1) * corr
        prof["W"] = Wm.mean(axis=0)
        prof["ratio"] = np.where(np.isfinite(r), r, np.nan)
        res["centre_over_local_weight"] = {"value": float(r[ic]), "se": float(np.std(rb[:, ic], ddof=1)) * corr}
    return res, prof, fold_out, Pr, (xm, ic, sx), runs, fold


def difference_test(Pa, Pb, stat, args, rng):
    """stat(mean profile of group a) - stat(mean profile of group b): the
    difference, its bootstrap standard error over the runs of each group,
    z and the permutation test's two-sided p value."""
    T = float(stat(Pa.mean(axis=0)) - stat(Pb.mean(axis=0)))
    ba = stat(Pa[boot_indices(rng, len(Pa), args.boot)].mean(axis=1))
    bb = stat(Pb[boot_indices(rng, len(Pb), args.boot)].mean(axis=1))
    se = float(np.sqrt(np.var(ba, ddof=1) * len(Pa) / (len(Pa) - 1) + np.var(bb, ddof=1) * len(Pb) / (len(Pb) - 1)))
    pooled = np.concatenate([Pa, Pb])
    na = len(Pa)
    count = 0
    for _ in range(args.perm):
        p = rng.permutation(len(pooled))
        t = stat(pooled[p[:na]].mean(axis=0)) - stat(pooled[p[na:]].mean(axis=0))
        count += abs(t) >= abs(T) - 1e-15
    return {"D_a_minus_D_b": T, "se": se, "z": T / se if se > 0 else None,
            "p_value": (1 + count) / (1 + args.perm)}


def compare(a, b, data, args, rng):
    Pa, (xa, ica, sxa) = data[a][:2]
    Pb, (xb, icb, sxb) = data[b][:2]
    if xa.shape != xb.shape or not np.allclose(xa, xb, rtol=0, atol=1e-9):
        die(2, "--compare %s,%s: the two groups have different grids (merged bins %d and %d)"
            % (a, b, xa.size, xb.size))
    old = difference_test(Pa, Pb, lambda P: dip_stats(P, ica, sxa)["D"], args, rng)
    out = {"a": a, "b": b, "runs": [len(Pa), len(Pb)], "D_a_minus_D_b": old["D_a_minus_D_b"],
           "se": old["se"], "z": old["z"], "permutations": args.perm, "p_value": old["p_value"]}
    # the fit estimator D_fit, on the base bins
    Ra, Rb, fold, win = data[a][2], data[b][2], data[a][3], args.fit_window
    if Ra.shape[1] != Rb.shape[1]:
        die(2, "--compare %s,%s: the two groups have different base grids" % (a, b))
    out["D_fit"] = difference_test(Ra, Rb, lambda P: fit_dip(P, fold, win, args.fit_ref)[0], args, rng)
    return out


# ---------------------------------------------------------------- outputs
def write_atomic(path, writer):
    d = os.path.dirname(os.path.abspath(path))
    tmp = os.path.join(d, ".%s.tmp%d" % (os.path.basename(path), os.getpid()))
    try:
        writer(tmp)
        os.replace(tmp, path)
    except OSError as e:
        if os.path.exists(tmp):
            os.unlink(tmp)
        die(3, "%s: cannot write (%s)" % (path, e))


def clean(v):
    if isinstance(v, dict):
        return {k: clean(w) for k, w in v.items()}
    if isinstance(v, (list, tuple)):
        return [clean(w) for w in v]
    if isinstance(v, (np.floating, float)):
        return None if not math.isfinite(float(v)) else float(v)
    if isinstance(v, np.integer):
        return int(v)
    return v


def main(argv):
    ap = argparse.ArgumentParser(prog=PROG, add_help=True,
                                 description="dip statistics of sand-pile base-pressure ensembles")
    ap.add_argument("groups", nargs="+", metavar="NAME=BASE.h5")
    ap.add_argument("-o", dest="out", required=True, metavar="STATS.json")
    ap.add_argument("--h5", metavar="PROFILES.h5")
    ap.add_argument("--csv", metavar="PROFILES.csv")
    ap.add_argument("--merge", type=int, default=5, help="base bins per bin (default 5)")
    ap.add_argument("--boot", type=int, default=4000)
    ap.add_argument("--perm", type=int, default=4000)
    ap.add_argument("--seed", type=int, default=34)
    ap.add_argument("--level", type=float, default=0.95)
    ap.add_argument("--target", type=float, default=0.05, help="dip depth to resolve at 3 SE")
    ap.add_argument("--g", type=float, default=9.81, help="gravity [m/s^2] for rho_b g h")
    ap.add_argument("--fit-window", type=float, default=0.06,
                    help="the fit estimator: largest distance s from the centre [m] (default 0.06: 30 d)")
    ap.add_argument("--fit-ref", type=float, default=0.02,
                    help="the fit estimator D_ref: reference distance [m] (default 0.02: 10 d)")
    ap.add_argument("--no-dumps", action="store_true", help="no local weight, no floor counts")
    ap.add_argument("--compare", action="append", default=[], metavar="A,B")
    ap.add_argument("--maps-h5", metavar="MAPS.h5", help="the groups' mean maps")
    ap.add_argument("--map-band", type=float, default=5.0, help="apex band |x - c| < B d (default 5)")
    ap.add_argument("--map-flanks", default="12:30", help="flank bands A d <= |x - c| < B d (default 12:30)")
    ap.add_argument("--map-surface", type=float, default=4.0, help="cells at least S d below the surface (4)")
    ap.add_argument("--map-floor", type=float, default=4.0, help="cells at least F d above the plate (4)")
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:
        return 1 if e.code else 0
    try:
        args.map_flanks = tuple(float(v) for v in args.map_flanks.split(":"))
        if len(args.map_flanks) != 2:
            raise ValueError
    except ValueError:
        print("%s: --map-flanks: expected A:B (grain diameters), got '%s'" % (PROG, args.map_flanks), file=sys.stderr)
        return 1
    if not (0 < args.map_band <= args.map_flanks[0] < args.map_flanks[1] and args.map_surface >= 0
            and args.map_floor >= 0):
        print("%s: expected 0 < --map-band <= A < B of --map-flanks, --map-surface >= 0, --map-floor >= 0" % PROG,
              file=sys.stderr)
        return 1
    if (args.boot < 100 or args.perm < 0 or not 0 < args.level < 1 or not args.target > 0
            or not 0 < args.fit_ref <= args.fit_window):
        print("%s: expected --boot >= 100, --perm >= 0, 0 < --level < 1, --target > 0, "
              "0 < --fit-ref <= --fit-window" % PROG, file=sys.stderr)
        return 1
    try:
        global h5py
        import h5py
    except ImportError:
        print("%s: h5py missing: run with /usr/bin/python3 (Debian's python3-h5py)" % PROG, file=sys.stderr)
        return 7
    try:
        rng = np.random.default_rng(args.seed)
        names, out, profs, data = [], {}, {}, {}
        for gdef in args.groups:
            name, eq, path = gdef.partition("=")
            if not eq or not name or not path:
                die(1, "%s: expected NAME=BASE.h5" % gdef)
            if name in out:
                die(1, "%s: group %s given twice" % (gdef, name))
            res, prof, fold, Pr, grid, base_runs, base_fold = summarise(name, path, args, rng)
            names.append(name)
            out[name], profs[name], data[name] = res, (prof, fold), (Pr, grid, base_runs, base_fold)
        comps = []
        for c in args.compare:
            a, comma, b = c.partition(",")
            if not comma or a not in out or b not in out:
                die(1, "--compare %s: expected A,B with two group names of %s" % (c, " ".join(names)))
            comps.append(compare(a, b, data, args, rng))
        doc = {"definition": {
            "D": "1 - F(0)/max F, F the mean profile folded about the centre, on bins of merge x dx",
            "interval": "basic bootstrap over the runs at level %g, %d resamples, seed %d"
                        % (args.level, args.boot, args.seed),
            "design": "runs for a dip depth of target at 3 SE: (3 sigma_run/target)^2, sigma_run = SE(D) sqrt(runs)",
            "D_fit": "1 - q(0)/max q over [0, fit_window], q(s) = a + b s + c s^2 least squares on the folded "
                     "profile's base bins with s <= fit_window (%g m); sd_runs: sd of the per-run values" % args.fit_window,
            "D_ref": "1 - q(0)/q(fit_ref) (%g m) of the same fit: signed, <= D_fit" % args.fit_ref,
            "map": "groups[*].map (run records with map.h5; scripts/dem/pile_map.py, docs/dem.md \"The density "
                   "and stress maps\"): phi_apex_minus_flanks = mean over the rows z of the mask of phi(|x - c| "
                   "< %g d) - (phi(left flank) + phi(right flank))/2, flanks %g d <= |x - c| < %g d, cells at "
                   "least %g d above the plate and %g d below the surface (phi = phi_bulk/2 of the mean map); "
                   "se_runs sd/sqrt(runs) of the per-run values, se_map from each map's rows; arch.K_apex = "
                   "sum sigma_xx / sum sigma_zz over the apex band's cells, arches when K_apex - 1 > 2 SE"
                   % (args.map_band, args.map_flanks[0], args.map_flanks[1], args.map_floor, args.map_surface)},
            "groups": out, "comparisons": comps}
        write_atomic(args.out, lambda t: open(t, "w").write(json.dumps(clean(doc), indent=1) + "\n"))
        if args.csv:
            def wcsv(t):
                with open(t, "w") as f:
                    f.write("group,kind,pos,value,lo,hi,se,W,ratio,ratio_se\n")
                    for nm in names:
                        prof, fold = profs[nm]
                        for i in range(prof["x"].size):
                            extra = ("%.9g,%.9g,%.9g" % (prof["W"][i], prof["ratio"][i], prof["ratio_se"][i])
                                     if "W" in prof else ",,")
                            f.write("%s,P,%.9g,%.9g,%.9g,%.9g,%.9g,%s\n" % (
                                nm, prof["x"][i], prof["P"][i], prof["P_lo"][i], prof["P_hi"][i], prof["P_se"][i], extra))
                        for i in range(fold["s"].size):
                            f.write("%s,F,%.9g,%.9g,%.9g,%.9g,%.9g,,,\n" % (
                                nm, fold["s"][i], fold["F"][i], fold["F_lo"][i], fold["F_hi"][i], fold["F_se"][i]))
            write_atomic(args.csv, wcsv)
        if args.h5:
            def wh5(t):
                with h5py.File(t, "w") as f:
                    f.attrs["definition"] = doc["definition"]["D"]
                    f.attrs["interval"] = doc["definition"]["interval"]
                    for nm in names:
                        prof, fold = profs[nm]
                        grp = f.create_group(nm)
                        for k, v in list(prof.items()) + list(fold.items()):
                            ds = grp.create_dataset(k, data=np.asarray(v, dtype=float))
                            ds.attrs["units"] = ("m" if k in ("x", "s") else "1" if k.startswith("ratio") else "Pa")
                        grp.attrs["D"] = out[nm]["D"]["value"]
                        grp.attrs["D_se"] = out[nm]["D"]["se"]
            write_atomic(args.h5, wh5)
        if args.maps_h5:
            units = {"x": "m", "z": "m", "h": "m", "mask": "1", "phi": "1", "phi_se": "1", "theta": "deg",
                     "lean": "deg"}

            def wmaps(t):
                with h5py.File(t, "w") as f:
                    f.attrs["definition"] = ("mean maps over each group's run records (scripts/dem/pile_map.py): "
                                             "[nz][nx]; sxx szz sxz = -(cxx czz cxz), compression positive; "
                                             "theta the major principal axis from the vertical (> 0 leaning to "
                                             "+x), lean = -theta sign(x - centre); mask the cells of the "
                                             "statistics")
                    for nm in names:
                        if nm not in MAPS:
                            continue
                        grp = f.create_group(nm)
                        for k, v in MAPS[nm].items():
                            ds = grp.create_dataset(k, data=np.asarray(v, dtype=float), compression="gzip")
                            ds.attrs["units"] = units.get(k, "Pa")
            write_atomic(args.maps_h5, wmaps)
    except Fail as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return e.code
    for nm in names:
        r = out[nm]
        print("%s: %d runs, D = %.4f +- %.4f (CI %.4f .. %.4f), halves %.4f +- %.4f, s_max %.4g m; "
              "runs for D = %g at 3 SE: %d" % (nm, r["runs"], r["D"]["value"], r["D"]["se"], r["D"]["ci"][0],
                                               r["D"]["ci"][1], r["D_halves"]["value"], r["D_halves"]["spread"],
                                               r["s_max"]["value"], args.target,
                                               r["design"]["runs_for_target_at_3se"]))
        print("%s: fit (s <= %g m): D_fit = %.4f +- %.4f (CI %.4f .. %.4f), D_ref = %.4f +- %.4f, sd over runs %.4f; "
              "runs for D = %g at 3 SE: %d" % (nm, args.fit_window, r["D_fit"]["value"], r["D_fit"]["se"],
                                               r["D_fit"]["ci"][0], r["D_fit"]["ci"][1], r["D_ref"]["value"],
                                               r["D_ref"]["se"], r["D_fit"]["sd_runs"], args.target,
                                               r["D_fit"]["design"]["runs_for_target_at_3se"]))
    for nm in names:
        mp = out[nm].get("map")
        if mp is None:
            print("%s: map: %s" % (nm, out[nm].get("map_missing")))
            continue
        dm, ar = mp["phi_apex_minus_flanks"], mp["arch"]
        print("%s: map: phi apex - flanks %s; K_apex %s, arches %s" % (
            nm, "%.4f +- %s (runs), +- %s (maps)" % (dm["value"], dm["se_runs"], dm["se_map"]) if dm else "none",
            "%.3f +- %s" % (ar["K_apex"]["value"], ar["K_apex"]["se_runs"]) if ar.get("K_apex") else "none",
            ar.get("arches")))
    for c in comps:
        print("%s - %s: %.4f +- %.4f, permutation p = %.4g; D_fit: %.4f +- %.4f, p = %.4g"
              % (c["a"], c["b"], c["D_a_minus_D_b"], c["se"], c["p_value"], c["D_fit"]["D_a_minus_D_b"],
                 c["D_fit"]["se"], c["D_fit"]["p_value"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
