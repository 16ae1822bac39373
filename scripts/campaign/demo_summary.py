#!/usr/bin/python3
"""demo_summary.py RES RUNS: the one-screen summary that ends `make demo`
(scripts/demo.sh): where the results are (RUNS: the continuum runs, RES: the
smoke campaign), the table and the figure to open first, and a few headline
numbers read from RES/scores.json (scripts/campaign/table.sh) with what they
mean. Paths are printed as given (demo.sh passes them relative to the
checkout), the figure as RES/figures/NAME.

Headline: per scenario, its first sweep point, phi and one key field (the
flow's velocity, vx or vz, where the scenario scores one, else the shear
stress sxz, else P): the EKM with the scenario files' own parameters (thesis)
against the reference engine (LAMMPS where it runs the scenario, else
LIGGGHTS, as the table's "By parameter set"), next to the floor (LIGGGHTS vs
LAMMPS); each cell relative L2 error / noise-normalised error, rounded as
scores.md rounds them. "n/a" where a comparison does not exist or a value is
null; a comparison that failed shows its status (missing, not steady).

Exit status (docs/exit-codes.md): 0 printed; 1 usage; 2 scores.json is not
a score table (one line naming it and what was expected); 3 it cannot be
read. A demo without scores must not look successful."""
import json
import math
import os
import sys

PROG = "demo_summary.py"
KEY_FIELDS = ("vx", "vz", "sxz", "P")  # the second field shown: the first the scenario scores
MAX_SCENARIOS = 6  # the screen: more are left to scores.md
FIGURE = "profiles_chute.png"  # the one to open first when there: EKM vs both engines' profiles


class Bad(Exception):
    """scores.json is not the score table: exit 2."""


def rounded(x, digits):
    """x rounded half away from zero to DIGITS decimals, printed as jq prints
    it (table.sh: round, tostring): no trailing .0."""
    scale = 10 ** digits
    v = math.copysign(math.floor(abs(x) * scale + 0.5) / scale, x)
    return str(int(v)) if v == int(v) else repr(v)


def number(cell, key, where):
    v = cell.get(key)
    if v is None:
        return "n/a"
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise Bad("%s.%s: expected a finite number or null, got %s" % (where, key, json.dumps(v)))
    return rounded(v, 3 if key == "rel_l2" else 2)


def cell_text(cell, where):
    """A comparison as scores.md's "By parameter set" shows it."""
    if cell is None:
        return "n/a"
    if not isinstance(cell, dict) or not isinstance(cell.get("status"), str):
        raise Bad("%s: expected an object with a \"status\"" % where)
    status = cell["status"]
    if status == "ok":
        return "%s / %s" % (number(cell, "rel_l2", where), number(cell, "noise_normalised", where))
    if status == "not_steady":
        return "not steady"
    return status + (" (%s)" % cell["reason"] if isinstance(cell.get("reason"), str) else "")


def no_constant(name):
    raise ValueError("%s is not JSON" % name)


def load(path):
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as e:
        msg = e.strerror if isinstance(e, OSError) and e.strerror else str(e)
        raise OSError("%s: cannot read (%s); expected the smoke campaign's score table "
                      "(make campaign SIZE=smoke)" % (path, msg)) from None
    try:
        d = json.loads(text, parse_constant=no_constant)
    except ValueError as e:
        raise Bad("%s: not JSON (%s); expected the campaign's score table "
                  "(scripts/campaign/table.sh)" % (path, e)) from None
    if not isinstance(d, dict) or not isinstance(d.get("rows"), list) or not d["rows"]:
        raise Bad("%s: expected an object with a non-empty list \"rows\" (the campaign's score "
                  "table, scripts/campaign/table.sh)" % path)
    for i, r in enumerate(d["rows"]):
        if not isinstance(r, dict) or not all(isinstance(r.get(k), str) for k in ("scenario", "point", "field")):
            raise Bad("%s: rows[%d]: expected an object with strings \"scenario\", \"point\" and "
                      "\"field\"" % (path, i))
    return d


def headline(d, path):
    """[(scenario, point label, field, engine, EKM cell, floor cell)], and the
    number of scenarios left out."""
    scen = {}  # scenario -> {"points": [point, ...], "rows": {(point, field): (index, row)}}
    for i, r in enumerate(d["rows"]):
        s = scen.setdefault(r["scenario"], {"points": [], "rows": {}})
        if r["point"] not in s["points"]:
            s["points"].append(r["point"])
        s["rows"][(r["point"], r["field"])] = (i, r)
    out = []
    for name in list(scen)[:MAX_SCENARIOS]:
        s = scen[name]
        point = s["points"][0]
        fields = [f for p, f in s["rows"] if p == point]
        shown = [f for f in ("phi",) if f in fields] + [f for f in KEY_FIELDS if f in fields][:1]
        label = point or "-"
        if len(s["points"]) > 1:
            label += " (1 of %d)" % len(s["points"])
        for f in shown or fields[:1]:
            i, r = s["rows"][(point, f)]
            where = "%s: rows[%d]" % (path, i)
            lammps = r.get("ekm_vs_lammps")
            ran = isinstance(lammps, dict) and lammps.get("status") != "n/a"
            engine = "lammps" if ran else "liggghts"
            out.append((name, label, f, engine, cell_text(r.get("ekm_vs_" + engine), where + ".ekm_vs_" + engine),
                        cell_text(r.get("liggghts_vs_lammps"), where + ".liggghts_vs_lammps")))
    return out, max(0, len(scen) - MAX_SCENARIOS)


def figure(res):
    """The figure to open first, named in RES/figures/figures.txt: FIGURE, else
    the first profiles PNG, else the first PNG; printed as RES/figures/NAME
    (make_figures.py writes there; figures.txt lists absolute paths). None
    when there is none."""
    try:
        with open(os.path.join(res, "figures", "figures.txt"), encoding="utf-8") as f:
            pngs = [os.path.basename(ln.strip()) for ln in f if ln.strip().endswith(".png")]
    except (OSError, UnicodeDecodeError):
        return None
    pick = [n for n in pngs if n == FIGURE] + [n for n in pngs if n.startswith("profiles_")] + pngs
    return os.path.join(res, "figures", pick[0]) if pick else None


def main():
    if len(sys.argv) != 3:
        print("%s: usage: demo_summary.py RESULTS_DIR RUNS_DIR" % PROG, file=sys.stderr)
        return 1
    res, runs = (a.rstrip("/") for a in sys.argv[1:])
    path = os.path.join(res, "scores.json")
    try:
        d = load(path)
        rows, more = headline(d, path)
    except OSError as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return 3
    except Bad as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return 2
    fig = figure(res)
    what = "the %s campaign" % d["size"] if isinstance(d.get("size"), str) else "the campaign"
    if isinstance(d.get("code_version"), str):
        what += " (code %s)" % d["code_version"]
    p = print
    p()
    p("== make demo: summary")
    p("Results:    %-26s every shipped scenario through ekm (.h5, .xdmf)" % (runs + "/"))
    p("            %-26s %s: scores, figures" % (res + "/", what))
    p("Open first: %-26s the score table: every scenario x point x field" % os.path.join(res, "scores.md"))
    if fig:
        profiles = os.path.basename(fig).startswith("profiles_")
        p("            %s%s" % (fig, "  EKM profiles over both DEM engines' (+-2 SE)" if profiles else ""))
    else:
        p("            (no figure: %s missing or without a PNG)" % os.path.join(res, "figures", "figures.txt"))
    p("Headline: relative L2 error ||EKM - DEM|| / ||DEM|| where both have material / noise-normalised")
    p("error (1 = as close as the DEM's own noise). EKM: the scenario files' own parameters (thesis)")
    p("vs LAMMPS, else LIGGGHTS; floor: LIGGGHTS vs LAMMPS; n/a: a pair not run.")
    fmt = "  %-15s %-20s %-5s %-8s %-17s %s"
    p(fmt % ("scenario", "point", "field", "EKM vs", "EKM", "floor"))
    for r in rows:
        p(fmt % r)
    if more:
        p("  (%d more scenario(s): %s)" % (more, os.path.join(res, "scores.md")))
    p("Smoke-size runs are short and noisy, so read these as a check that the whole chain runs; the")
    p("floor (LIGGGHTS vs LAMMPS) is the best any model can do; the reference numbers are in")
    p("results/scores.md (committed, from `make campaign SIZE=ref`).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
