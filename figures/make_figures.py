#!/usr/bin/python3
"""make_figures.py: the paper figures of a validation campaign.

    /usr/bin/python3 figures/make_figures.py --size smoke|ref RES

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
                          EKM runs and the EKM's closed form (MODEL.md 7)
  cost                    wall time of DEM (per engine) and EKM per scenario

Every input is read and checked before anything is drawn. A missing file,
dataset or attribute stops with one line on stderr naming it and what it
is for, exit status 1, and no figures.txt (a previous one is removed once
drawing starts). Usage errors: exit status 2.
"""
import argparse
import os
import sys

sys.dont_write_bytecode = True          # no __pycache__ in the source tree
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import common as C  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(prog=C.PROG, description="Paper figures of a campaign results folder.")
    ap.add_argument("--size", choices=("smoke", "ref"), required=True, help="campaign size")
    ap.add_argument("res", help="results folder (results/smoke or results)")
    a = ap.parse_args(argv)
    if not os.path.isdir(a.res):
        print("%s: %s: missing (the campaign results folder)" % (C.PROG, a.res), file=sys.stderr)
        return 1
    try:
        import numpy  # noqa: F401
        import h5py  # noqa: F401
        import matplotlib  # noqa: F401
    except ImportError as e:
        print("%s: %s (install scripts/deps/figures.txt; use /usr/bin/python3)" % (C.PROG, e),
              file=sys.stderr)
        return 1
    C.style()
    try:
        scenarios, notes = C.load_campaign(a.res, a.size)
    except C.InputError as e:
        print("%s: %s" % (C.PROG, e), file=sys.stderr)
        return 1
    for n in notes:
        print("%s: note: %s" % (C.PROG, n), file=sys.stderr)

    import profiles
    import spacetime
    import rheology
    import cost

    outdir = os.path.join(a.res, "figures")
    listing = os.path.join(outdir, "figures.txt")
    previous = []
    if os.path.isfile(listing):
        with open(listing) as fh:
            previous = [l.strip() for l in fh if l.strip()]
        os.remove(listing)
    w = C.Writer(outdir)
    try:
        profiles.make(scenarios, w)
        spacetime.make(scenarios, w)
        for n in rheology.make(scenarios, w) + cost.make(scenarios, w):
            print("%s: note: %s" % (C.PROG, n), file=sys.stderr)
    except C.InputError as e:
        print("%s: %s" % (C.PROG, e), file=sys.stderr)
        return 1
    # figures of a previous run that this one did not make again
    now = {os.path.basename(p) for p in w.written}
    for p in previous:
        b = os.path.basename(p)
        old = os.path.join(outdir, b)
        if b not in now and b.endswith((".pdf", ".png")) and os.path.isfile(old):
            os.remove(old)
    w.finish()
    print("%s: %d files in %s (listed in figures.txt)" % (C.PROG, len(w.written), outdir))
    return 0


if __name__ == "__main__":
    sys.exit(main())
