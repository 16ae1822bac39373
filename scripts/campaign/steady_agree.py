#!/usr/bin/python3
"""steady_agree.py NEWTON.h5 RUN.h5 TOL: does `ekm steady`'s state (NEWTON)
agree with the steady state `ekm run` reached from the scenario's initial
state (RUN, [run] stop = steady)?  The campaign (scripts/campaign/ekm_step.sh)
uses the Newton state only when it does: Newton can converge to a fixed
point of the stepper the initial state does not flow to (the chute at 30
degrees: a layer without the run's dilute top tail), and the one a
comparison with DEM needs is the one the initial state flows to.

Agreement: the run ended steady (root attribute steady = 1), and for phi,
vx, T and P of the last frames, max |NEWTON - RUN| <= TOL x max |RUN| (the
run stops at its drift criterion, close to, not at, the fixed point:
ekm_step.sh passes TOL 5e-2), phi over the column, vx, T and P where both
have material (phi >= 0.1 of the run's largest phi in both: the scores'
common support, docs/compare.md; a dilute tail the run has not yet grown
to its end would otherwise count its surface velocity as the difference),
and the gap (a pressure-held wall) within TOL relative.
Prints one line; exit 0: agree, 1: disagree, 2: a file that is not such
an output."""
import sys

import h5py
import numpy as np

SUPPORT = 0.1  # of the run's largest phi: the scores' common support (compare/score.h CG_SCORE_SUPPORT)


def last(f, name):
    if name not in f:
        raise KeyError("%s: no dataset /%s (expected an ekm output)" % (f.filename, name))
    d = f[name]
    return np.asarray(d[-1] if d.ndim == 2 else d[-1:])


def main():
    if len(sys.argv) != 4:
        print("steady_agree.py: usage: steady_agree.py NEWTON.h5 RUN.h5 TOL", file=sys.stderr)
        return 1
    try:
        tol = float(sys.argv[3])
        with h5py.File(sys.argv[1], "r") as a, h5py.File(sys.argv[2], "r") as b:
            if float(b.attrs.get("steady", 0)) != 1.0:
                print("the time-stepped run did not end steady (steady = %s)" % b.attrs.get("steady", "absent"))
                return 1
            worst, where = 0.0, ""
            names = ["phi", "vx", "T", "P"] + (["gap"] if "gap" in a and "gap" in b else [])
            phi_a, phi_b = last(a, "phi"), last(b, "phi")
            if phi_a.shape != phi_b.shape:
                raise KeyError("/phi: %s cells vs %s" % (phi_a.shape, phi_b.shape))
            support_phi = SUPPORT * float(np.max(phi_b))
            support = (phi_a >= support_phi) & (phi_b >= support_phi)
            if not support.any():
                print("disagree: no cell has material (phi >= %g) in both states" % support_phi)
                return 1
            for n in names:
                x, y = last(a, n), last(b, n)
                if x.shape != y.shape:
                    raise KeyError("/%s: %s cells vs %s" % (n, x.shape, y.shape))
                if n in ("vx", "T", "P"):
                    x, y = x[support], y[support]
                scale = float(np.max(np.abs(y))) if y.size else 0.0
                diff = float(np.max(np.abs(x - y))) if y.size else 0.0
                rel = diff / scale if scale > 0 else (0.0 if diff == 0 else np.inf)
                if not np.isfinite(rel):
                    rel = np.inf
                if rel > worst or not where:
                    worst, where = rel, n
            ok = worst <= tol
            print("%s: largest difference %.3g of the run's maximum (%s; tolerance %g)"
                  % ("agree" if ok else "disagree", worst, where, tol))
            return 0 if ok else 1
    except (OSError, KeyError, ValueError) as e:
        print("steady_agree.py: %s" % e, file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
