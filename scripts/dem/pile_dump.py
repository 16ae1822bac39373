"""pile_dump.py: reading sand-pile runs, shared by pile_stats.py and pile_summary.py.

    last_frame(path) -> Frame(step, bx, ly, cols, rows)
        the last frame of a LAMMPS/LIGGGHTS text dump: its step, box x bounds
        (lo, hi) [m], box y period [m], column names (ITEM: ATOMS), rows (one
        list of strings per atom)
    read_vars(run_dir) -> {name: float}       a run's vars.txt
    plate_half_width(run_dir, lx) -> lp / 2 [m] of vars.txt; without lp, lx
        (every grain of the box is over the plate: the issue-15 floor)
    on_plate(x, z, xmid, half) -> bool        a pile grain on the plate: its
        centre above the plate's top (z > 0) and within its width
        (|x - xmid| < half, xmid the box's middle); one sliding off the
        plate's edge is not part of the pile (docs/dem.md "Sand pile")

Errors raise DumpError(code, message): code 2 bad input (no frame, a
truncated frame), 3 a file missing; each script turns it into its own
one-line message and exit status.
"""
import collections
import os

Frame = collections.namedtuple("Frame", "step bx ly cols rows")


class DumpError(Exception):
    def __init__(self, code, msg):
        super().__init__(msg)
        self.code = code


def last_frame(path):
    if not os.path.exists(path):
        raise DumpError(3, "%s: no such file" % path)
    frame = None
    with open(path) as f:
        lines = iter(f)
        try:
            for line in lines:
                if not line.startswith("ITEM: TIMESTEP"):
                    continue
                step = int(next(lines))
                head = next(lines)
                while not head.startswith("ITEM: NUMBER OF ATOMS"):
                    head = next(lines)
                n = int(next(lines))
                next(lines)  # ITEM: BOX BOUNDS
                bx = [float(v) for v in next(lines).split()[:2]]
                by = [float(v) for v in next(lines).split()[:2]]
                next(lines)
                cols = next(lines).split()[2:]
                rows = [next(lines).split() for _ in range(n)]
                frame = Frame(step, bx, by[1] - by[0], cols, rows)
        except StopIteration:
            raise DumpError(2, "%s: the last frame is cut short" % path) from None
    if frame is None:
        raise DumpError(2, "%s: expected a LAMMPS/LIGGGHTS dump, found no ITEM: TIMESTEP" % path)
    return frame


def read_vars(run):
    out = {}
    path = os.path.join(run, "vars.txt")
    if not os.path.isfile(path):
        raise DumpError(3, "%s: no such file" % path)
    with open(path) as f:
        for line in f:
            k, eq, v = line.partition("=")
            if eq:
                try:
                    out[k.strip()] = float(v)
                except ValueError:
                    pass
    return out


def plate_half_width(run, lx):
    path = os.path.join(run, "vars.txt")
    if os.path.exists(path):
        lp = read_vars(run).get("lp")
        if lp is not None:
            return 0.5 * lp
    return lx


def on_plate(x, z, xmid, half):
    return (z > 0) & (abs(x - xmid) < half)
