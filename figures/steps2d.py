#!/usr/bin/python3
"""steps2d.py: how the 2D box filling's results depend on the step size
(scripts/steps2d.sh runs it; docs/model/twod.md "The step's accuracy in 2D").

    /usr/bin/python3 figures/steps2d.py --runs RUNS -o OUTDIR

RUNS holds the runs of scripts/steps2d.sh (NAME.h5, `ekm run` of
scenarios/thesis_filling_2d.ini); NAME is SET_rN (thermal_relax_step N),
SET_lN (solid_lag_tol N) or SET_dN (dt_max N, "none": the step's own
limits). The runs of one SET
differ only in that number; each is compared with the finest of its set
(the smallest N, the one with the most steps). Writes into OUTDIR, under
temporary names renamed when complete:

  steps2d.json   per run: steps, wall time, the numbers below and their
                 differences from the finest run of the set, each
                 {"value", "units"}; the inputs' provenance
  steps2d.md     the same as a table

The numbers (filling2d.py's definitions, at the monitoring point x =
0.04 m, z = 0.05 m and at the last frame, t = 4 s):
  bed_arrival   the first frame whose phi at the monitoring cell exceeds
                phi_co [s] (frames 0.05 s apart)
  T_mon         T at the monitoring cell at the end [m^2/s^2] (log10
                difference)
  P_max         the largest P over the bed cells (phi > 0.5) [Pa]
  floor_share   the floor's normal force over the weight of the box's
                content: sum over the bottom row of (-szz + rho_p phi g
                dz/2) dx, the cell's stress taken to the floor with the
                lower half cell's weight, over g times the mass
  mass_error    (mass in the box - mass entered) / mass entered
  phi_bed       the largest phi difference from the finest run over the
                cells of the last frame that are bed cells (phi > 0.5)
                below the topmost bed cell of their column in both runs
                (the partly filled surface cells, whose phi says where
                the surface lies within them, are column_mass's)
  column_mass   the largest difference of a column's content (sum of phi
                dz) from the finest run, over the mean column's content
  P             the largest P difference over the cells wet in both runs,
                over the finest run's P_max

Exit status (docs/exit-codes.md): 0 done; 1 usage; 2 bad input; 3 a run
missing or unreadable, or an output that cannot be written; 7 a Python
package missing.
"""
import glob
import json
import math
import os
import re
import signal
import sys

sys.dont_write_bytecode = True          # no __pycache__ in the source tree
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import common as C  # noqa: E402
import filling2d as F  # noqa: E402
from pile2d import ArgParser, q, num, write_atomic  # noqa: E402

PROG = "steps2d.py"
UNAVAILABLE = 7
NAME = re.compile(r"^([a-z0-9]+)_([rdl])(none|[0-9.e+-]+)$")
KNOB = {"r": ("numerics.thermal_relax_step", "1"), "d": ("numerics.dt_max", "s"),
        "l": ("numerics.solid_lag_tol", "1")}


def knob_value(s):
    return math.inf if s == "none" else float(s)


def numbers(path):
    """The run's numbers (module comment) and its last frame's phi and P."""
    import numpy as np
    run = F.Run(path)
    ix, iz = run.cell(*F.DEFAULT_POINT)
    res = F.analyse(run, ix, iz, F.DEFAULT_POINT)
    m = run.mat
    with C._open(path, "a run of scripts/steps2d.sh") as f:
        g = C._attr(f, path, "gravity.magnitude", "the floor's share of the weight")
        mass_in = C._attr(f, path, "stats.mass_in", "the mass balance")
        steps = C._attr(f, path, "stats.steps", "the step count")
        wall = C._attr(f, path, "stats.wall_time_s", "the wall time")
    phi, szz = run.phi[-1], run.szz[-1]
    mass = float(phi.sum()) * run.dx * run.dz * m["rho_p"]
    floor = float(np.sum(-szz[0] + m["rho_p"] * phi[0] * g * run.dz / 2)) * run.dx
    fin = res["final"]
    arr = res["key_times"]["bed_arrival"]["time"]["value"]
    r = C.rel(path)
    if arr is None or fin["P_max"]["value"] is None or not fin["P_max"]["value"] > 0:
        raise C.InputError("%s: no bed at the monitoring point or no bed cell at the end (a filling run to "
                           "its end is expected: scripts/steps2d.sh)" % r)
    if not mass_in > 0:
        raise C.InputError("%s: root attribute 'stats.mass_in' = %g: expected the mass entered, > 0" % (r, mass_in))
    return {"steps": int(steps), "wall_s": float(wall),
            "bed_arrival": arr, "T_mon": float(run.T[-1][iz, ix]),
            "P_max": fin["P_max"]["value"], "floor_share": floor / (g * mass),
            "mass_error": (mass - mass_in) / mass_in,
            "_phi": phi, "_P": run.P[-1], "_wet": run.regime[-1] > 0, "_dz": run.dz,
            "_grid": (run.x.size, run.z.size, run.dx, run.dz), "_t": float(run.t[-1])}


def interior_bed(phi):
    """Bed cells (phi > BED_PHI) below the topmost bed cell of their column."""
    import numpy as np
    bed = phi > F.BED_PHI
    top = np.zeros_like(bed)
    for k in range(phi.shape[1]):
        rows = np.nonzero(bed[:, k])[0]
        if rows.size:
            top[rows[-1], k] = True
    return bed & ~top


def main(argv=None):
    def stop(signum, _frame):
        raise SystemExit(128 + signum)
    for sig in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT):
        signal.signal(sig, stop)
    ap = ArgParser(prog=PROG, description="The 2D filling's step-size study (scripts/steps2d.sh).")
    ap.add_argument("--runs", required=True, help="the folder of the study's runs (NAME.h5)")
    ap.add_argument("-o", dest="outdir", required=True, help="folder for steps2d.json and steps2d.md")
    a = ap.parse_args(argv)
    try:
        import numpy as np
        import h5py  # noqa: F401
    except ImportError as e:
        print("%s: %s (install scripts/deps/figures.txt; use /usr/bin/python3)" % (PROG, e),
              file=sys.stderr)
        return UNAVAILABLE
    sets = {}
    for path in sorted(glob.glob(os.path.join(a.runs, "*.h5"))):
        mt = NAME.match(os.path.basename(path)[:-3])
        if mt:
            try:
                v = knob_value(mt.group(3))
            except ValueError:
                print("%s: %s: expected SET_rN.h5, SET_lN.h5 or SET_dN.h5 with N a number or 'none'"
                      % (PROG, C.rel(path)), file=sys.stderr)
                return C.BAD_INPUT
            sets.setdefault((mt.group(1), mt.group(2)), []).append((v, path))
    if not sets:
        print("%s: %s: no run named SET_rN.h5, SET_lN.h5 or SET_dN.h5 (scripts/steps2d.sh)" % (PROG, C.rel(a.runs)),
              file=sys.stderr)
        return C.IO_ERROR
    out = {"program": "figures/steps2d.py", "definitions": __doc__.split("The numbers")[1].strip(),
           "sets": {}}
    md = ["| run | %s | steps | wall [s] | bed arrival [s] | T_mon [m^2/s^2] | P_max [Pa] | floor share "
          "| mass error | max dphi (bed) | max dcolumn | max dP/P_max |" % "knob",
          "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    try:
        for (name, kind), runs in sorted(sets.items()):
            runs.sort()
            got = [(v, p, numbers(p)) for v, p in runs]
            ref = got[0][2]
            knob, units = KNOB[kind]
            rows = []
            for v, p, r in got:
                if r["_grid"] != ref["_grid"] or abs(r["_t"] - ref["_t"]) > 1e-9 * max(ref["_t"], 1.0):
                    raise C.InputError("%s: %d x %d cells to t = %g s: expected the grid and end of %s of the "
                                       "same set (%d x %d cells, t = %g s)"
                                       % (C.rel(p), r["_grid"][0], r["_grid"][1], r["_t"],
                                          os.path.basename(runs[0][1]), ref["_grid"][0], ref["_grid"][1],
                                          ref["_t"]))
                both = interior_bed(r["_phi"]) & interior_bed(ref["_phi"])
                if not np.any(both):
                    raise C.InputError("%s: no interior bed cell (phi > %g below its column's surface cell) in "
                                       "common with %s" % (C.rel(p), F.BED_PHI, os.path.basename(runs[0][1])))
                dphi = float(np.abs(r["_phi"] - ref["_phi"])[both].max())
                col, col_ref = r["_phi"].sum(axis=0) * r["_dz"], ref["_phi"].sum(axis=0) * ref["_dz"]
                dcol = float(np.abs(col - col_ref).max() / col_ref.mean())
                wet = r["_wet"] & ref["_wet"]
                dP = float(np.abs(r["_P"] - ref["_P"])[wet].max()) / ref["P_max"]
                row = {"run": os.path.basename(p), knob: q(num(v) if math.isfinite(v) else None, units,
                                                          *(() if math.isfinite(v) else ("none",))),
                       "input": C.Run2D.provenance(F.Run(p)),
                       "steps": q(r["steps"], "1"), "wall_time": q(num(r["wall_s"]), "s"),
                       "bed_arrival": q(num(r["bed_arrival"]), "s"),
                       "T_mon": q(num(r["T_mon"]), "m^2/s^2"), "P_max": q(num(r["P_max"]), "Pa"),
                       "floor_share": q(num(r["floor_share"]), "1"),
                       "mass_error": q(num(r["mass_error"]), "1"),
                       "max_dphi_bed_from_finest": q(num(dphi), "1"),
                       "max_dcolumn_mass_from_finest": q(num(dcol), "1"),
                       "max_dP_from_finest_over_P_max": q(num(dP), "1")}
                rows.append(row)
                md.append("| %s | %s | %d | %.1f | %.2f | %.2e | %.1f | %.4f | %.1e | %.2g | %.2g | %.2g |"
                          % (os.path.basename(p)[:-3], "none" if not math.isfinite(v) else "%g" % v,
                             r["steps"], r["wall_s"], r["bed_arrival"], r["T_mon"], r["P_max"],
                             r["floor_share"], r["mass_error"], dphi, dcol, dP))
            out["sets"]["%s_%s" % (name, kind)] = {"knob": knob, "finest": os.path.basename(runs[0][1]),
                                                   "runs": rows}
    except C.InputError as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return e.status
    try:
        text = json.dumps(out, indent=1, allow_nan=False) + "\n"
    except ValueError as e:      # a NaN slipped through: a bug, not an input problem
        print("%s: internal error: %s" % (PROG, e), file=sys.stderr)
        return 5
    try:
        os.makedirs(a.outdir, exist_ok=True)
        write_atomic(os.path.join(a.outdir, "steps2d.json"), text)
        write_atomic(os.path.join(a.outdir, "steps2d.md"),
                     "# The 2D filling's step-size study (scripts/steps2d.sh, figures/steps2d.py)\n\n"
                     "knob: thermal_relax_step (runs *_rN), solid_lag_tol (*_lN) or dt_max in s (*_dN); differences from "
                     "the first row of each set; wall times with other runs on the machine's "
                     "other core (results/bench.md has the timings).\n\n" + "\n".join(md) + "\n")
    except OSError as e:
        print("%s: %s: cannot write (%s)" % (PROG, C.rel(e.filename or a.outdir), e.strerror or e),
              file=sys.stderr)
        return C.IO_ERROR
    print("%s: %s: steps2d.json, steps2d.md" % (PROG, a.outdir))
    return 0


if __name__ == "__main__":
    sys.exit(main())
