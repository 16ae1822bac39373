#!/usr/bin/python3
"""make_figures.py: the paper figures of a validation campaign.

    /usr/bin/python3 figures/make_figures.py --size smoke|ref [--ekm PATH] RES

RES is a campaign results folder (results/smoke or results; make campaign,
make figures). Writes PDF and PNG (300 dpi) under RES/figures/, each under
a temporary name renamed when complete, and last RES/figures/figures.txt,
the list of the files written (one path a line):

  profiles_<S>[_<P>]      EKM profiles over DEM profiles (+-2 SE bands) of
                          every scenario S (sweep point P; a few points, the
                          chute angles, share one figure as colours)
  <S>_phi_map, <S>_bed_height
                          a time-series scenario (filling): space-time maps
                          phi(z, t) of DEM and EKM, and the bed height h(t)
  rheology_simple_shear   P and |sxz|/P against shear rate at each phi: DEM,
                          EKM runs and the EKM's closed form (docs/model-notes.md section 7)
  rheology_fit            mu(I), phi(I), P/(rho_p d^2 gdot^2), T/(d gdot)^2
                          against phi: DEM of both simple-shear sweeps, the
                          closed form of every parameter set, residuals
  calibration_matrix      the train/test matrix (RES/calibration.json)
  cost                    wall time of DEM (per engine) and EKM per scenario
  maps_<S>_<P>            a 2D scenario (the sand pile, scored by ekmcompare
                          score2d): phi and sigma_zz maps of each engine and
                          the EKM (every parameter set), sigma_zz along the base

Every input is read and checked before anything is drawn. A missing or
malformed input stops with one line on stderr naming it and what it is
for, and no figures.txt (a previous one is removed once drawing starts).
Exit status (docs/exit-codes.md): 0 done; 1 usage; 2 bad input (a dataset,
attribute or key missing or not as expected); 3 a file missing or
unreadable, or an output that cannot be written; 7 a Python package
missing (numpy, h5py, matplotlib) or the ekm program (--ekm, default
build/continuum/ekm of this checkout: `ekm homog` gives the EKM's
closed-form rheology). SIGTERM and SIGHUP (and SIGINT) end it
with 128+N after removing the temporary of the figure being written.
"""
import argparse
import os
import signal
import sys

sys.dont_write_bytecode = True          # no __pycache__ in the source tree
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import common as C  # noqa: E402


USAGE = 1          # exit statuses, docs/exit-codes.md (common.py: 2, 3)
UNAVAILABLE = 7


class ArgParser(argparse.ArgumentParser):
    """argparse with the table's usage status (argparse's own is 2, which
    the table gives to bad input)."""

    def error(self, message):
        self.print_usage(sys.stderr)
        self.exit(USAGE, "%s: %s\n" % (self.prog, message))


class SignalStop:
    """A signal ends the program as an exception, so that the `finally`
    clauses remove the temporaries; the status is the shell's 128+N. The
    signal is also recorded: an exception raised while Python runs a
    finalizer (__del__, a weakref callback) is printed and dropped, so
    `check` raises it again before anything is committed."""

    def __init__(self):
        self.signum = 0

    def __call__(self, signum, _frame):
        self.signum = signum
        raise SystemExit(128 + signum)

    def check(self):
        if self.signum:
            raise SystemExit(128 + self.signum)


def main(argv=None):
    stop = SignalStop()
    for sig in (signal.SIGTERM, signal.SIGHUP, signal.SIGINT):
        signal.signal(sig, stop)
    ap = ArgParser(prog=C.PROG, description="Paper figures of a campaign results folder.")
    ap.add_argument("--size", choices=("smoke", "ref"), required=True, help="campaign size")
    ap.add_argument("--ekm", default=C.default_ekm(),
                    help="the ekm program, for `ekm homog` (default: %(default)s)")
    ap.add_argument("res", help="results folder (results/smoke or results)")
    a = ap.parse_args(argv)
    if not os.path.isdir(a.res):
        print("%s: %s: missing (the campaign results folder)" % (C.PROG, a.res), file=sys.stderr)
        return C.IO_ERROR
    try:
        import numpy  # noqa: F401
        import h5py  # noqa: F401
        import matplotlib  # noqa: F401
    except ImportError as e:
        print("%s: %s (install scripts/deps/figures.txt; use /usr/bin/python3)" % (C.PROG, e),
              file=sys.stderr)
        return UNAVAILABLE
    C.style()
    import profiles
    import spacetime
    import rheology
    import calibration
    import cost
    import pilemaps
    # every input read and every closed form evaluated before any drawing
    try:
        scenarios, notes = C.load_campaign(a.res, a.size)
        sets, set_notes = C.load_sets(a.res)
        matrix, matrix_notes = calibration.load(a.res)
        rheo = rheology.prepare(scenarios, a.ekm, os.path.dirname(HERE), sets)
    except C.InputError as e:
        print("%s: %s" % (C.PROG, e), file=sys.stderr)
        return e.status
    for n in notes + set_notes + matrix_notes:
        print("%s: note: %s" % (C.PROG, n), file=sys.stderr)

    outdir = os.path.join(a.res, "figures")
    try:
        return draw(outdir, scenarios, [ps.name for ps in sets], rheo, matrix,
                    (profiles, spacetime, rheology, calibration, cost, pilemaps), stop)
    except C.InputError as e:
        print("%s: %s" % (C.PROG, e), file=sys.stderr)
        return e.status
    except OSError as e:
        print("%s: %s: cannot write (%s)" % (C.PROG, C.rel(e.filename or outdir), e.strerror or e),
              file=sys.stderr)
        return C.IO_ERROR


def draw(outdir, scenarios, set_names, rheo, matrix, modules, stop):
    """Every figure into outdir, then the listing figures.txt (not after a
    signal: stop.check())."""
    profiles, spacetime, rheology, calibration, cost, pilemaps = modules
    listing = os.path.join(outdir, "figures.txt")
    previous = []
    if os.path.isfile(listing):
        with open(listing) as fh:
            previous = [l.strip() for l in fh if l.strip()]
        os.remove(listing)
    w = C.Writer(outdir)
    profiles.make(scenarios, w, set_names)
    spacetime.make(scenarios, w)
    for n in (rheology.make(rheo, w) + calibration.make(matrix, w) + cost.make(scenarios, w)
              + pilemaps.make(scenarios, w, set_names)):
        print("%s: note: %s" % (C.PROG, n), file=sys.stderr)
    # figures of a previous run that this one did not make again
    now = {os.path.basename(p) for p in w.written}
    for p in previous:
        b = os.path.basename(p)
        old = os.path.join(outdir, b)
        if b not in now and b.endswith((".pdf", ".png")) and os.path.isfile(old):
            os.remove(old)
    stop.check()
    w.finish()
    print("%s: %d files in %s (listed in figures.txt)" % (C.PROG, len(w.written), outdir))
    return 0


if __name__ == "__main__":
    sys.exit(main())
