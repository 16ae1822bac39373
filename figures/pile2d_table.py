#!/usr/bin/python3
"""pile2d_table.py: one markdown table of 2D piles' numbers at their base
times, from the pile2d.json of every folder of DIR (figures/pile2d.py).

    /usr/bin/python3 figures/pile2d_table.py DIR OUT.md --title TITLE --about TEXT
                                              [--dem SUMMARY.json]

A row per folder (sorted by name): its base time, bed kind, height, the
two flank angles with their standard errors, phi under the apex minus the
flanks, P(centre)/P(max), pile2d's 3-sigma dip test and the run's code
version. With --dem, a row per group of a DEM summary
(scripts/dem/pile_analysis.sh's summary-<law>-SIZE.json: the records'
mean +- SE over seeds; p(centre)/p(max) of the floor's normal stress).
TEXT is the paragraph under the title (what wrote the table, from what).
OUT.md is written under a temporary name and renamed when complete.
A folder holding `ekmcompare score2d` outputs (score2d-*.json: a pile
against a DEM mean map, or one engine's map against the other's) adds a
row per file to a second table: the relative L2 error of phi, sxx, szz
and sxz over the common support and over the map's interior, with the
points of each.
Used by scripts/thesis2d.sh and scripts/dem/pile_ekm.sh.
Exit status: 0; 2 a pile2d.json or the summary unreadable or without its
numbers (one line naming the file); 3 DIR or an output folder missing.
"""
import argparse
import json
import os
import sys


def fail(code, msg):
    print("pile2d_table.py: " + msg, file=sys.stderr)
    sys.exit(code)


def v(q, fmt, scale=1.0):
    return "-" if q is None or q.get("value") is None else fmt % (q["value"] * scale)


def pile_row(name, j):
    b, bp = j["base_time"], j["base_time"]["base_pressure"]
    slopes = ", ".join("-" if b[k]["angle"].get("value") is None else
                       v(b[k]["angle"], "%.1f") + " +- " + v(b[k].get("se"), "%.1f")
                       for k in ("slope_left", "slope_right"))
    dip = b["dip"]["value"]
    return "| %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
        name, v(b["time"], "%g"), b["bed"], v(b["height"], "%.1f", 1e3), slopes,
        v(b["phi_apex_minus_flank"], "%+.1e"), v(bp["ratio_centre_to_max"], "%.3f"),
        "-" if dip is None else ("yes" if dip else "no"), j["input"]["code_version"])


def dem_row(g):
    def pm(k, fmt, scale=1.0):
        if g.get(k) is None:
            return "-"
        se = g.get(k + "_se")
        return (fmt % (g[k] * scale)) + ("" if se is None else " +- " + fmt % (se * scale))
    return "| DEM %s %s (%d seed%s) | at rest | pile | %s | %s, %s | - | %s | - | - |" % (
        g["engine"], g["point"], g["seeds"], "" if g["seeds"] == 1 else "s", pm("height", "%.1f", 1e3),
        pm("angle_left", "%.1f"), pm("angle_right", "%.1f"), pm("p_centre_over_max", "%.3f"))


SCORE_FIELDS = ("phi", "sxx", "szz", "sxz")


def score_row(name, j):
    def rel(field):
        f = j["fields"].get(field)
        if f is None:
            return "-"
        # the support's metric at the field's level, the interior's under "interior"
        return " / ".join("-" if r is None or r.get("rel_l2") is None else "%.3f" % r["rel_l2"]
                          for r in (f, f.get("interior")))
    phi = j["fields"]["phi"]
    model = j["model"]
    against = model["group"] if model["group"] else "t = %g s" % model["t_s"]
    pts = "%d / %s" % (phi["points"], phi["interior"]["points"] if phi.get("interior") else "-")
    return "| %s | %s | %s | %s | %s |" % (name, against, j["dem"]["group"], pts,
                                          " | ".join(rel(f) for f in SCORE_FIELDS))


def main():
    ap = argparse.ArgumentParser(description="the table of 2D piles' numbers (pile2d.json)")
    ap.add_argument("dir")
    ap.add_argument("out")
    ap.add_argument("--title", required=True)
    ap.add_argument("--about", required=True)
    ap.add_argument("--dem")
    a = ap.parse_args()
    if not os.path.isdir(a.dir):
        fail(3, "%s: no such folder" % a.dir)
    rows = []
    for name in sorted(os.listdir(a.dir)):
        path = os.path.join(a.dir, name, "pile2d.json")
        if not os.path.isfile(path):
            continue
        try:
            with open(path) as fh:
                rows.append(pile_row(name, json.load(fh)))
        except (OSError, ValueError, KeyError, TypeError, AttributeError) as e:
            fail(2, "%s: expected pile2d.py's numbers (%s: %s)" % (path, type(e).__name__, e))
    scores = []
    for name in sorted(os.listdir(a.dir)):
        folder = os.path.join(a.dir, name)
        if not os.path.isdir(folder):
            continue
        for fn in sorted(f for f in os.listdir(folder) if f.startswith("score2d-") and f.endswith(".json")):
            path = os.path.join(folder, fn)
            try:
                with open(path) as fh:
                    scores.append(score_row(name, json.load(fh)))
            except (OSError, ValueError, KeyError, TypeError, AttributeError) as e:
                fail(2, "%s: expected ekmcompare score2d's JSON (%s: %s)" % (path, type(e).__name__, e))
    if a.dem:
        try:
            with open(a.dem) as fh:
                rows += [dem_row(g) for g in json.load(fh)["groups"]]
        except (OSError, ValueError, KeyError, TypeError) as e:
            fail(2, "%s: expected pile_analysis.sh's summary groups (%s: %s)" % (a.dem, type(e).__name__, e))
    text = ("# %s\n\n%s\n\n"
            "| folder | t [s] | bed | height [mm] | slopes left, right [deg] (+- se) "
            "| phi apex - flank | P(centre)/P(max) | dip (3 sigma) | code |\n"
            "|---|---|---|---|---|---|---|---|---|\n" % (a.title, a.about) + "\n".join(rows) + "\n")
    if scores:
        text += ("\n## Against the DEM's mean maps (ekmcompare score2d)\n\n"
                 "Relative L2 error over the common support / the map's interior (docs/compare.md "
                 "\"Scoring a 2D pile\"; stresses compression positive). The engine floor rows score "
                 "one engine's map against the other's.\n\n"
                 "| folder | model | DEM map | points | phi | sxx | szz | sxz |\n"
                 "|---|---|---|---|---|---|---|---|\n" + "\n".join(scores) + "\n")
    tmp = a.out + ".tmp"
    try:
        with open(tmp, "w") as fh:
            fh.write(text)
        os.replace(tmp, a.out)
    except OSError as e:
        if os.path.exists(tmp):
            os.unlink(tmp)
        fail(3, "%s: cannot write (%s)" % (a.out, e.strerror))


if __name__ == "__main__":
    main()
