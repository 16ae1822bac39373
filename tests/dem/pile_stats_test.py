#!/usr/bin/python3
"""pile_stats_test.py: scripts/dem/pile_stats.py on synthetic piles.

    tests/dem/pile_stats_test.py EKMCOMPARE WORKDIR

Synthetic ensembles of wedge piles on a plate (the reference geometry: a
130 d box, a 102 d plate of floor grains on the lattice x = (i + 1/2) d, 4
grains across y), written as LAMMPS dumps: each floor grain carries fz =
-p(x) d^2 (1 + noise), noise normal with sd 0.5 (independent grains), the
pile's top grains give the surface h(x) = H (1 - |x - c| / 51 d) and their
mass makes rho_b = 1500 kg/m^3. p(x) = rho_b g h(x) (1 + A s / 51 d), s = |x - c|:
with A = 3 its maximum is at s = 17 d, 1/3 above p(0) (a dip of 0.25; 0.18
on 10 d bins), with A = 0 it is the local weight (no dip); a third kind,
p = rho_b g min(h, h(25 d)), is flat-topped (no dip, the hard case: noise
on a plateau makes the estimated D > 0).
The dumps go through `ekmcompare base --last 1` and then pile_stats.py:

  1. a dip (A = 3, 16 runs): the dip depth D of the same profile without
     noise (the same pipeline) lies inside the noisy ensemble's 95%
     interval, and the interval excludes 0;
  2. no dip (A = 0, 16 runs): the interval covers 0; p(0) / rho_b g h(0)
     is 1 within 3 SE; the floor counts are aligned (deviation 0); the
     flat-topped profile (16 runs): its interval covers 0 too;
  3. the permutation test: dip against no dip p < 0.01; no dip against
     another no-dip ensemble p > 0.05;
  4. coverage: over 200 ensembles of 12 runs of each kind (numpy, the
     module's own functions) the 95% interval covers the true D (0, 0 and
     0.174) in at least 80% (measured: 100%, 92%, 92%; another 200 at 12
     runs: 100%, 96%, 92%, and at 4 runs 100%, 88%, 82%);
  5. the fit estimator D_fit (a quadratic in s fitted to the folded 2 d
     profile over s <= 30 d, 1 - q(0)/max q): the noiseless dip (its true
     depth 0.25: p ~ (1 - u)(1 + 3u) is quadratic in s, maximum at s = 17
     d) gives 0.245 +- 0.01 (10 d bins: 0.171); the noisy one (16 runs):
     its interval covers the noiseless value and excludes 0, and the SE
     times sqrt(16) is the per-run sd within a factor 1.5; no dip
     (noiseless, p = rho_b g h): D_fit < 0.005 and D_ref = 1 - q(0)/q(10 d)
     = -0.241 +- 0.01; no dip, noisy: D_fit < 0.03, D_ref below 0 by 3 SE;
     the noiseless flat top (p flat over s < 25 d): D_fit = 0.054 +- 0.005,
     the estimator's documented bias on that shape (docs/dem.md); the
     permutation test on D_fit separates the dip from no dip (p < 0.01);
  6. bad input: one line on stderr naming the file, and the documented
     exit status: a file that is not HDF5 (2), a missing file (3), an
     HDF5 with one run (2), NAME=FILE without '=' (1), --compare between
     different grids (2), a dump named by the HDF5 that is gone (3), a fit
     window wider than the plate (2).
Exit 0 if every check holds, 1 otherwise (one line per failed check).
"""
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
STATS = os.path.join(ROOT, "scripts", "dem", "pile_stats.py")
sys.path.insert(0, os.path.join(ROOT, "scripts", "dem"))
import pile_stats  # noqa: E402

D = 0.002
LX, LY, PLATE = 130 * D, 4 * D, 102 * D
RHO_B, G, H = 1500.0, 9.81, 20 * D
failures = []


def check(ok, what):
    print(("ok: " if ok else "FAILED: ") + what)
    if not ok:
        failures.append(what)


def profile(xc, amp):
    """(h, p) at xc; amp < 0: the flat-topped no-dip profile (p = rho_b g
    min(h, h(25 d)): a plateau over the central 50 d)."""
    s = np.abs(xc - LX / 2)
    u = s / (PLATE / 2)
    h = np.clip(H * (1 - u), 0, None)
    if amp < 0:
        return h, RHO_B * G * np.minimum(h, H * (1 - 25 / 51))
    return h, RHO_B * G * h * (1 + amp * u)


def write_dump(path, rng, amp, noise):
    cols = np.arange(int(round((LX - PLATE) / 2 / D)), int(round((LX + PLATE) / 2 / D)))
    rows, aid = [], 0
    for i in cols:
        x = (i + 0.5) * D
        _, p = profile(np.array([x]), amp)
        for j in range(4):
            aid += 1
            f = -p[0] * D * D * (1 + noise * rng.standard_normal())
            rows.append("%d 2 %.9g %.9g %.9g %.9g %.9g %.9g" % (aid, x, (j + 0.5) * D, -0.5 * D, 0.5 * D, 1e-5, f))
    # the surface: one grain per 2 d bin whose top is h(x) at the bin's centre
    bins = np.arange(7, 58) * 2 * D + D
    h, _ = profile(bins, amp)
    keep = h > D
    mass = RHO_B * LY * (h[keep].sum() * 2 * D) / keep.sum()
    for x, hh in zip(bins[keep], h[keep]):
        aid += 1
        rows.append("%d 1 %.9g %.9g %.9g %.9g %.9g 0" % (aid, x, 0.5 * LY, hh - 0.5 * D, 0.5 * D, mass))
    with open(path, "w") as f:
        f.write("ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n%d\nITEM: BOX BOUNDS pp pp fm\n" % len(rows))
        f.write("0 %.9g\n0 %.9g\n%.9g %.9g\n" % (LX, LY, -1.5 * D, 40 * D))
        f.write("ITEM: ATOMS id type x y z radius mass fz\n" + "\n".join(rows) + "\n")


def ensemble(ekmcompare, work, name, amp, noise, runs, seed):
    rng = np.random.default_rng(seed)
    dumps = []
    for r in range(runs):
        p = os.path.join(work, "%s-run%d.dump" % (name, r))
        write_dump(p, rng, amp, noise)
        dumps.append(p)
    out = os.path.join(work, name + ".h5")
    subprocess.run([ekmcompare, "base", "--last", "1", "--quiet", "-o", out] + dumps, check=True)
    return out


def stats(*args):
    return subprocess.run(["/usr/bin/python3", STATS] + list(args), capture_output=True, text=True)


def one_line_error(r, code, name, what):
    lines = r.stderr.strip().split("\n")
    check(r.returncode == code and len(lines) == 1 and lines[0].startswith("pile_stats: ") and name in lines[0],
          "%s: exit %d and one line naming %s (got %d, %r)" % (what, code, name, r.returncode, r.stderr.strip()))


def main():
    if len(sys.argv) != 3:
        print("usage: pile_stats_test.py EKMCOMPARE WORKDIR", file=sys.stderr)
        return 2
    ekmcompare, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    dip = ensemble(ekmcompare, work, "dip", 3.0, 0.5, 16, 1)
    exact = ensemble(ekmcompare, work, "exact", 3.0, 0.0, 2, 2)
    flat = ensemble(ekmcompare, work, "nodip", 0.0, 0.5, 16, 3)
    flat2 = ensemble(ekmcompare, work, "nodip2", 0.0, 0.5, 16, 4)
    plateau = ensemble(ekmcompare, work, "plateau", -1.0, 0.5, 16, 7)
    exact0 = ensemble(ekmcompare, work, "exact0", 0.0, 0.0, 2, 8)
    exactflat = ensemble(ekmcompare, work, "exactflat", -1.0, 0.0, 2, 9)
    out = os.path.join(work, "stats.json")
    r = stats("-o", out, "--h5", os.path.join(work, "prof.h5"), "--csv", os.path.join(work, "prof.csv"),
              "--boot", "2000", "--perm", "2000", "--compare", "dip,nodip", "--compare", "nodip,nodip2",
              "dip=" + dip, "exact=" + exact, "nodip=" + flat, "nodip2=" + flat2, "plateau=" + plateau,
              "exact0=" + exact0, "exactflat=" + exactflat)
    check(r.returncode == 0, "pile_stats on the synthetic ensembles exits 0 (%s)" % r.stderr.strip())
    if r.returncode != 0:
        return 1
    print(r.stdout, end="")
    s = json.load(open(out))
    g = s["groups"]
    true_d = g["exact"]["D"]["value"]
    lo, hi = g["dip"]["D"]["ci"]
    check(0.15 < true_d < 0.2, "the noiseless dip depth on 10 d bins is %.4f (0.18 expected)" % true_d)
    check(lo <= true_d <= hi, "dip: the true D %.4f inside the interval [%.4f, %.4f]" % (true_d, lo, hi))
    check(lo > 0 and g["dip"]["resolved"], "dip: the interval excludes 0 (lower bound %.4f)" % lo)
    check(abs(g["dip"]["D_halves"]["value"] - true_d) < 3 * g["dip"]["D_halves"]["se"],
          "dip: the halves' estimate %.4f within 3 SE of %.4f" % (g["dip"]["D_halves"]["value"], true_d))
    lo, hi = g["nodip"]["D"]["ci"]
    check(lo <= 0 <= hi, "no dip: the interval [%.4f, %.4f] covers 0" % (lo, hi))
    lo, hi = g["plateau"]["D"]["ci"]
    check(lo <= 0 <= hi,
          "flat top: D = %.4f, its interval [%.4f, %.4f] covers 0" % (g["plateau"]["D"]["value"], lo, hi))
    c = g["nodip"]["centre_over_local_weight"]
    check(abs(c["value"] - 1) < 3 * c["se"], "no dip: p(0)/rho_b g h(0) = %.4f +- %.4f, 1 within 3 SE" % (c["value"], c["se"]))
    check(abs(g["nodip"]["rho_b"]["mean"] - RHO_B) < 0.02 * RHO_B,
          "no dip: rho_b %.1f kg/m^3 from the dumps (built with %g)" % (g["nodip"]["rho_b"]["mean"], RHO_B))
    check(g["nodip"]["floor_count_max_deviation"] == 0 and g["nodip"]["floor_grains_per_bin"] == 8,
          "the 2 d bins are aligned with the floor lattice: 8 grains in every bin")
    check(abs(g["exact"]["s_max"]["value"] - 20 * D) < 1e-9,
          "the noiseless maximum at s = 20 d (got %.4g m)" % g["exact"]["s_max"]["value"])
    comp = {(x["a"], x["b"]): x for x in s["comparisons"]}
    check(comp[("dip", "nodip")]["p_value"] < 0.01, "permutation: dip vs no dip p = %.4g < 0.01" % comp[("dip", "nodip")]["p_value"])
    check(comp[("nodip", "nodip2")]["p_value"] > 0.05,
          "permutation: two no-dip ensembles p = %.4g > 0.05" % comp[("nodip", "nodip2")]["p_value"])
    # 5. the fit estimator
    q = g["exact"]["D_fit"]["value"]
    check(abs(q - 0.25) < 0.01, "fit: the noiseless dip depth 0.25 recovered as D_fit = %.4f (+- 0.01)" % q)
    lo, hi = g["dip"]["D_fit"]["ci"]
    check(lo <= q <= hi and lo > 0, "fit: dip, 16 noisy runs: [%.4f, %.4f] covers %.4f and excludes 0" % (lo, hi, q))
    fd = g["dip"]["D_fit"]
    ratio = fd["se"] * 4 / fd["sd_runs"]
    check(1 / 1.5 < ratio < 1.5, "fit: dip: SE sqrt(16) = %.4f against the per-run sd %.4f (ratio %.2f, within 1.5)"
          % (fd["se"] * 4, fd["sd_runs"], ratio))
    q0, r0 = g["exact0"]["D_fit"]["value"], g["exact0"]["D_ref"]["value"]
    check(q0 < 0.005 and abs(r0 + 0.241) < 0.01,
          "fit: no dip, noiseless: D_fit = %.4f (< 0.005), D_ref = %.4f (-0.241 +- 0.01)" % (q0, r0))
    nd = g["nodip"]
    check(nd["D_fit"]["value"] < 0.03 and nd["D_ref"]["value"] + 3 * nd["D_ref"]["se"] < 0,
          "fit: no dip, noisy: D_fit = %.4f (< 0.03), D_ref = %.4f +- %.4f (below 0 by 3 SE)"
          % (nd["D_fit"]["value"], nd["D_ref"]["value"], nd["D_ref"]["se"]))
    qf = g["exactflat"]["D_fit"]["value"]
    check(abs(qf - 0.054) < 0.005, "fit: flat top (noiseless): D_fit = %.4f, the documented bias 0.054 +- 0.005" % qf)
    check(comp[("dip", "nodip")]["D_fit"]["p_value"] < 0.01,
          "fit: permutation dip vs no dip p = %.4g < 0.01" % comp[("dip", "nodip")]["D_fit"]["p_value"])
    # 4. coverage, on profiles made directly (the module's functions)
    rng = np.random.default_rng(5)
    x = (np.arange(65) + 0.5) * 2 * D
    groups, ic = pile_stats.merge_plan(65, 5, "coverage")
    xm = pile_stats.merged(x, groups)
    sx = np.abs(xm - LX / 2)
    for amp, label in ((0.0, "no dip"), (-1.0, "flat top"), (3.0, "dip")):
        _, p = profile(x, amp)
        p[(x < 14 * D) | (x > 116 * D)] = np.nan
        truth = float(pile_stats.dip_stats(pile_stats.merged(p, groups), ic, sx)["D"])
        cover = 0
        for _ in range(200):
            runs = p * (1 + 0.5 / np.sqrt(8) * rng.standard_normal((12, 65)))
            Pr = pile_stats.merged(runs, groups)
            t = pile_stats.dip_stats(Pr.mean(axis=0), ic, sx)["D"]
            b = pile_stats.dip_stats(Pr[pile_stats.boot_indices(rng, 12, 1000)].mean(axis=1), ic, sx)["D"]
            lo, hi = pile_stats.interval(t, b, 0.95, 12)
            cover += lo <= truth <= hi
        check(cover >= 160, "coverage, %s: the 95%% interval covers D = %.4f in %d of 200 ensembles (>= 160)"
              % (label, truth, cover))
    # 5. bad input
    bad = os.path.join(work, "not.h5")
    open(bad, "w").write("not hdf5\n")
    one_line_error(stats("-o", out, "a=" + bad), 2, bad, "not an HDF5 file")
    gone = os.path.join(work, "missing.h5")
    one_line_error(stats("-o", out, "a=" + gone), 3, gone, "a missing file")
    single = ensemble(ekmcompare, work, "single", 0.0, 0.5, 1, 6)
    one_line_error(stats("-o", out, "a=" + single), 2, single, "one run")
    one_line_error(stats("-o", out, dip), 1, dip, "NAME=FILE without '='")
    other = os.path.join(work, "other.h5")
    subprocess.run([ekmcompare, "base", "--last", "1", "--quiet", "--dx", "%g" % (4 * D), "-o", other]
                   + [os.path.join(work, "nodip-run%d.dump" % k) for k in range(3)], check=True)
    one_line_error(stats("-o", out, "--merge", "3", "--no-dumps", "--compare", "a,b", "a=" + flat, "b=" + other),
                   2, "--compare a,b", "different grids")
    os.rename(os.path.join(work, "nodip-run0.dump"), os.path.join(work, "moved.dump"))
    one_line_error(stats("-o", out, "a=" + flat), 3, "nodip-run0.dump", "a dump named by the HDF5 is gone")
    one_line_error(stats("-o", out, "--no-dumps", "--fit-window", "0.2", "--fit-ref", "0.02", "a=" + dip), 2, dip,
                   "a fit window wider than the plate")
    check(not [f for f in os.listdir(work) if ".tmp" in f], "no temporary file left behind")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
