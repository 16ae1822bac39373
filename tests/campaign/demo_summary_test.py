#!/usr/bin/python3
"""demo_summary_test.py SOURCE_DIR WORK_DIR: scripts/campaign/demo_summary.py
(the summary that ends `make demo`) on the committed fixture
demo_summary/scores.json (the smoke campaign's table trimmed to 8 rows):
exit 0, at most 25 lines of at most 100 columns, the result folders, the
table and the figure to open first named, the headline numbers the fixture's
(as scores.md rounds them), n/a for the floor of a pair not run, no NaN. And
a score table that is malformed (demo_summary/malformed.json: "rows" not a
list), not JSON (the fixture cut short) or missing: one error line naming
the file, nothing on stdout, exit 2 (bad input) or 3 (cannot read)."""
import json
import os
import shutil
import subprocess
import sys

src, work = sys.argv[1], sys.argv[2]
script = os.path.join(src, "scripts", "campaign", "demo_summary.py")
fixtures = os.path.join(src, "tests", "campaign", "demo_summary")
fails = []


def check(ok, what):
    if not ok:
        fails.append(what)


def run(res):
    p = subprocess.run(["/usr/bin/python3", "-B", script, res, "runs/demo/continuum"], cwd=work,
                       capture_output=True, text=True, timeout=60)
    return p.returncode, p.stdout, p.stderr


def results(name, scores):
    """WORK/NAME/ with scores.json from SCORES (a path, or bytes), and a
    figures.txt that lists absolute paths as make_figures.py writes them."""
    res = os.path.join(work, name)
    os.makedirs(os.path.join(res, "figures"))
    if isinstance(scores, bytes):
        with open(os.path.join(res, "scores.json"), "wb") as f:
            f.write(scores)
    elif scores:
        shutil.copy(scores, os.path.join(res, "scores.json"))
    with open(os.path.join(res, "figures", "figures.txt"), "w") as f:
        for n in ("cost.pdf", "cost.png", "profiles_chute.pdf", "profiles_chute.png", "rheology_fit.png"):
            f.write(os.path.join(res, "figures", n) + "\n")
    return name


shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
fixture = os.path.join(fixtures, "scores.json")
with open(fixture) as f:
    table = json.load(f)

# the fixture: the summary
rc, summary, err = run(results("results/smoke", fixture))
out = summary
lines = out.splitlines()
check(rc == 0, "exit status %d, expected 0 (stderr: %s)" % (rc, err.strip()))
check(err == "", "stderr not empty: %r" % err)
check(0 < len(lines) <= 25, "%d lines, expected 1 to 25" % len(lines))
check(all(len(ln) <= 100 for ln in lines), "a line longer than 100 columns")
check("nan" not in out.lower(), "NaN printed")
for path in ("runs/demo/continuum/", "results/smoke/", "results/smoke/scores.md",
             "results/smoke/figures/profiles_chute.png", "results/scores.md", "make campaign SIZE=ref"):
    check(path in out, "%s not named" % path)
check("smoke campaign (code %s)" % table["code_version"] in out, "the campaign's size and code version not named")
# (scenario, point shown, field, engine, EKM rel_l2 / noise-normalised, floor): each
# the fixture's row, rounded as scores.md rounds it (3 and 2 decimals)
expect = [("chute", "-", "phi", "lammps", "0.087 / 51.57", "0.012 / 4.37"),
          ("chute", "-", "vx", "lammps", "30.959 / 305.38", "0.124 / 0.86"),
          ("simple_shear", "-", "phi", "lammps", "0.009 / 2.65", "n/a"),
          ("simple_shear", "-", "sxz", "lammps", "0.866 / 9.86", "n/a"),
          ("simple_shear_p", "p10-rate10 (1 of 2)", "phi", "lammps", "0.102 / 64.72", "n/a"),
          ("simple_shear_p", "p10-rate10 (1 of 2)", "sxz", "lammps", "0.283 / 3.81", "n/a")]
shown = [ln for ln in lines if ln.startswith("  ") and ln.split()[0] in {r["scenario"] for r in table["rows"]}]
check(len(shown) == len(expect), "%d headline rows, expected %d" % (len(shown), len(expect)))
for e, ln in zip(expect, shown):
    words = [e[0]] + e[1].split() + list(e[2:4]) + e[4].split() + e[5].split()
    check(ln.split() == words, "headline row %r, expected %s" % (ln, " ".join(words)))
for s, pt, f, eng, ekm, floor in expect:
    r = next(r for r in table["rows"] if r["scenario"] == s and r["field"] == f and
             (r["point"] or "-") == pt.split()[0])
    for text, cell in ((ekm, r["ekm_vs_" + eng]), (floor, r["liggghts_vs_lammps"])):
        if text == "n/a":
            check(cell["status"] == "n/a", "%s %s: n/a shown for a cell with status %s" % (s, f, cell["status"]))
            continue
        rel, nn = (float(x) for x in text.split(" / "))
        check(abs(rel - cell["rel_l2"]) <= 5e-4 and abs(nn - cell["noise_normalised"]) <= 5e-3,
              "%s %s: %s is not the fixture's %s / %s" % (s, f, text, cell["rel_l2"], cell["noise_normalised"]))

# malformed, not JSON, missing: one line naming the file, exit 2 / 2 / 3
with open(fixture, "rb") as f:
    cut = f.read()[:2000]
for name, scores, code, says in (("malformed", os.path.join(fixtures, "malformed.json"), 2, 'non-empty list "rows"'),
                                 ("cut", cut, 2, "not JSON"),
                                 ("missing", None, 3, "cannot read")):
    rc, out, err = run(results(name, scores))
    check(rc == code, "%s: exit status %d, expected %d" % (name, rc, code))
    check(out == "", "%s: stdout not empty: %r" % (name, out[:200]))
    errl = err.splitlines()
    check(len(errl) == 1 and errl[0].startswith("demo_summary.py: %s/scores.json: " % name) and says in errl[0],
          "%s: expected one line naming %s/scores.json (%s), got %r" % (name, name, says, err))

for f in fails:
    print("FAIL: " + f, file=sys.stderr)
if fails:
    print("the summary of the fixture:\n" + summary, file=sys.stderr)
    sys.exit(1)
print("demo_summary_test: all passed")
