#!/usr/bin/python3
"""figures_test.py: tests of figures/make_figures.py on synthetic results
folders (make_synthetic.py), written under WORK (the build directory).

    /usr/bin/python3 figures_test.py SOURCE_DIR WORK CASE FIELDS_JSON EKM

FIELDS_JSON: build/generated/fields.json (the field schema the synthetic
files take their units from). EKM: the built ekm program (`ekm homog`).

CASE:
  complete-ref    ref layout (sweep points): every expected figure, PDF and
                  PNG non-empty, exactly those listed in figures.txt
  complete-smoke  the same for the smoke layout (single cases)
  missing         one input file removed at a time (an EKM run next to its
                  DEM profiles, a DEM manifest, a score file, scores.json): exit status 3,
                  one line on stderr naming the file, no figures.txt, no
                  figure at all
  failed-step     a DEM step that failed (comparison 'missing' in the table,
                  no CG file): a note, every figure still made
  bad-data        a dataset removed / of the wrong shape / without units, a
                  score without options, an EKM /z without a row per
                  output: exit status 2, the message names file and
                  dataset (or key); and the shift is the score's: a score
                  with another shift draws a different profile; the EKM's
                  cell centres are /z's rows (an older /z stretched by
                  /gap draws the same profile, unmoving rows another)
  exit-codes      the other statuses of docs/exit-codes.md: usage 1 (an
                  unknown option, no --size), a Python package missing 7,
                  figures.txt that cannot be written 3 (no temporary left),
                  SIGTERM while drawing 143 (no temporary left)
  sets            the parameter sets: every calibration/<set>/fit.ini in
                  rheology_fit and every ekm_<set>.h5 in the profiles (the
                  figures change without them), a set without fit.ini a
                  note; the closed forms are ekm homog's (residuals of the
                  synthetic sweep); calibration.json's cells in the matrix;
                  a bad fit.ini or matrix cell 2, no ekm program 7
Exit status 77 (skipped) when /usr/bin/python3 lacks matplotlib or h5py.
"""
import os
import shutil
import subprocess
import sys

EXPECTED = {
    "ref": ["profiles_chute", "profiles_filling", "profiles_shear_cell",
            "profiles_simple_shear_phi0.50-rate5", "profiles_simple_shear_phi0.50-rate10",
            "profiles_simple_shear_phi0.53-rate5", "profiles_simple_shear_phi0.53-rate10",
            "profiles_simple_shear_p",
            "filling_phi_map", "filling_bed_height", "rheology_simple_shear", "rheology_fit",
            "calibration_matrix", "cost"],
    "smoke": ["profiles_chute", "profiles_filling", "profiles_shear_cell", "profiles_simple_shear",
              "profiles_simple_shear_p",
              "filling_phi_map", "filling_bed_height", "rheology_simple_shear", "rheology_fit", "cost"],
}

failures = []
FIELDS_JSON = []   # [path]: set by main() from the command line
EKM = []           # [path of the ekm program]: set by main()


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL: " + msg, file=sys.stderr)


def synth(src, out, layout):
    if os.path.exists(out):
        shutil.rmtree(out)
    subprocess.run([sys.executable, os.path.join(src, "tests", "figures", "make_synthetic.py"),
                    "--layout", layout, "--fields", FIELDS_JSON[0], out], check=True)


def figures(src, res, size, extra=(), env=None):
    p = subprocess.run([sys.executable, os.path.join(src, "figures", "make_figures.py"),
                        "--size", size, "--ekm", EKM[0], res] + list(extra), capture_output=True, text=True,
                       env=env)
    return p.returncode, p.stdout, p.stderr


def complete(src, work, layout):
    res = os.path.join(work, "complete-" + layout)
    synth(src, res, layout)
    rc, out, err = figures(src, res, layout)
    check(rc == 0, "%s: exit status %d, stderr: %s" % (layout, rc, err.strip()))
    listing = os.path.join(res, "figures", "figures.txt")
    check(os.path.isfile(listing), "%s: no %s" % (layout, listing))
    if not os.path.isfile(listing):
        return
    with open(listing) as fh:
        listed = [l.strip() for l in fh if l.strip()]
    want = sorted(os.path.join(res, "figures", "%s.%s" % (s, e))
                  for s in EXPECTED[layout] for e in ("pdf", "png"))
    check(sorted(listed) == want, "%s: figures.txt lists %s, expected %s"
          % (layout, sorted(os.path.basename(p) for p in listed),
             sorted(os.path.basename(p) for p in want)))
    for p in want:
        check(os.path.isfile(p) and os.path.getsize(p) > 1000, "%s: %s missing or empty" % (layout, p))
        if p.endswith(".png") and os.path.isfile(p):
            with open(p, "rb") as fh:
                check(fh.read(8) == b"\x89PNG\r\n\x1a\n", "%s: %s is not a PNG" % (layout, p))
        if p.endswith(".pdf") and os.path.isfile(p):
            with open(p, "rb") as fh:
                body = fh.read()
            check(body.startswith(b"%PDF"), "%s: %s is not a PDF" % (layout, p))
            check(b"CreationDate" not in body, "%s: %s has a CreationDate" % (layout, p))
    leftovers = [f for f in os.listdir(os.path.join(res, "figures")) if f.endswith(".tmp")]
    check(not leftovers, "%s: temporary files left: %s" % (layout, leftovers))
    # a second run writes the same figures (deterministic output)
    with open(os.path.join(res, "figures", "cost.pdf"), "rb") as fh:
        first = fh.read()
    rc, _, err = figures(src, res, layout)
    with open(os.path.join(res, "figures", "cost.pdf"), "rb") as fh:
        check(rc == 0 and fh.read() == first, "%s: a second run wrote a different cost.pdf" % layout)


def failed_step(src, work):
    """A failed DEM step (the table marks the comparison 'missing', its CG
    file and manifest were never made): left out with a note, the rest drawn."""
    import json
    res = os.path.join(work, "failed")
    synth(src, res, "smoke")
    js_path = os.path.join(res, "scores.json")
    with open(js_path) as fh:
        js = json.load(fh)
    for row in js["rows"]:
        if row["scenario"] == "chute":
            row["ekm_vs_liggghts"] = {"status": "missing", "file": "chute/score_ekm_liggghts.json"}
            row["liggghts_vs_lammps"] = {"status": "missing"}
    with open(js_path, "w") as fh:
        json.dump(js, fh)
    os.remove(os.path.join(res, "chute", "cg_liggghts.h5"))
    os.remove(os.path.join(res, "chute", "dem_liggghts.json"))
    os.remove(os.path.join(res, "chute", "score_ekm_liggghts.json"))
    rc, out, err = figures(src, res, "smoke")
    check(rc == 0, "failed step: exit status %d, stderr: %s" % (rc, err.strip()))
    check("chute" in err and "cg_liggghts.h5" in err and "note" in err,
          "failed step: no note naming chute/cg_liggghts.h5: %s" % err.strip())
    listing = os.path.join(res, "figures", "figures.txt")
    listed = open(listing).read().split() if os.path.isfile(listing) else []
    want = [os.path.join(res, "figures", "%s.%s" % (s, e)) for s in EXPECTED["smoke"] for e in ("pdf", "png")]
    check(sorted(listed) == sorted(want), "failed step: figures.txt lists %s" % listed)


def expect_failure(src, res, size, needle, what, status):
    rc, out, err = figures(src, res, size)
    lines = err.strip().splitlines()
    check(rc == status, "%s: exit status %d, expected %d (stderr: %s)" % (what, rc, status, err.strip()))
    check(len(lines) == 1, "%s: expected one line on stderr, got %d: %r" % (what, len(lines), err))
    for n in needle:
        check(n in err, "%s: stderr does not name %r: %s" % (what, n, err.strip()))
    figdir = os.path.join(res, "figures")
    check(not os.path.exists(os.path.join(figdir, "figures.txt")), "%s: figures.txt written" % what)
    made = os.listdir(figdir) if os.path.isdir(figdir) else []
    check(not made, "%s: files written in %s: %s" % (what, figdir, made))


def missing(src, work):
    base = os.path.join(work, "missing-base")
    synth(src, base, "ref")
    cases = [
        ("chute/theta24/ekm.h5", ["chute/theta24/ekm.h5", "missing", "EKM run"]),
        ("filling/dem_lammps.json", ["filling/dem_lammps.json", "missing", "wall time"]),
        ("scores.json", ["scores.json", "missing", "score table"]),
        ("chute/theta22/score_ekm_lammps.json", ["chute/theta22/score_ekm_lammps.json", "missing", "shift"]),
        ("simple_shear/phi0.53-rate10/cg_lammps.h5",
         ["simple_shear/phi0.53-rate10/cg_lammps.h5", "missing"]),
    ]
    for i, (rm, needle) in enumerate(cases):
        res = os.path.join(work, "missing-%d" % i)
        if os.path.exists(res):
            shutil.rmtree(res)
        shutil.copytree(base, res)
        os.remove(os.path.join(res, rm))
        expect_failure(src, res, "ref", needle, "without " + rm, 3)


def bad_data(src, work):
    import h5py
    import numpy as np
    base = os.path.join(work, "bad-base")
    synth(src, base, "smoke")
    res = os.path.join(work, "bad-0")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    with h5py.File(os.path.join(res, "shear_cell", "cg_liggghts.h5"), "a") as f:
        del f["sxz_se"]
    expect_failure(src, res, "smoke", ["shear_cell/cg_liggghts.h5", "/sxz_se", "missing"],
                   "without dataset /sxz_se", 2)
    res = os.path.join(work, "bad-1")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    with h5py.File(os.path.join(res, "filling", "ekm.h5"), "a") as f:
        a = f["phi"][()]
        del f["phi"]
        f["phi"] = np.asarray(a)[:, :-1]
    expect_failure(src, res, "smoke", ["filling/ekm.h5", "/phi", "shape"], "phi of the wrong shape", 2)
    res = os.path.join(work, "bad-2")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    with h5py.File(os.path.join(res, "chute", "ekm.h5"), "a") as f:
        del f.attrs["stats.wall_time_s"]
    expect_failure(src, res, "smoke", ["chute/ekm.h5", "stats.wall_time_s"], "without stats.wall_time_s", 2)
    res = os.path.join(work, "bad-3")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    with h5py.File(os.path.join(res, "chute", "cg_lammps.h5"), "a") as f:
        del f["T"].attrs["units"]
    expect_failure(src, res, "smoke", ["chute/cg_lammps.h5", "/T", "units"], "dataset /T without units", 2)
    res = os.path.join(work, "bad-4")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    edit_options(os.path.join(res, "filling", "score_ekm_liggghts.json"), lambda o: o.pop("shift_m"))
    expect_failure(src, res, "smoke", ["filling/score_ekm_liggghts.json", "options.shift_m"],
                   "score without options.shift_m", 2)
    res = os.path.join(work, "bad-5")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    edit_options(os.path.join(res, "filling", "score_ekm_lammps.json"), lambda o: o.update(ekm_time="first"))
    expect_failure(src, res, "smoke", ["filling/score_ekm_lammps.json", "options.ekm_time", "first"],
                   "score with a bad options.ekm_time", 2)
    # the shift is the score's: 5 mm more for LAMMPS in shear_cell moves its profiles
    rc, _, err = figures(src, base, "smoke")
    check(rc == 0, "bad-data base: exit status %d: %s" % (rc, err.strip()))
    res = os.path.join(work, "shifted")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    edit_options(os.path.join(res, "shear_cell", "score_ekm_lammps.json"), lambda o: o.update(shift_m=0.005))
    rc, _, err = figures(src, res, "smoke")
    check(rc == 0, "shifted: exit status %d: %s" % (rc, err.strip()))
    for stem, same in (("profiles_shear_cell", False), ("profiles_chute", True)):
        with open(os.path.join(base, "figures", stem + ".png"), "rb") as a, \
                open(os.path.join(res, "figures", stem + ".png"), "rb") as b:
            check((a.read() == b.read()) == same, "shifted: %s.png %s" % (
                stem, "differs (not shifted)" if same else "is the same: the score's shift_m was not used"))
    # the EKM's cell centres are its /z of each output (shear_cell's top wall
    # moves them): an output from before /z had a row per output (/z the
    # first output's centres, stretched by /gap) draws the same profiles;
    # rows that do not move draw others
    with h5py.File(os.path.join(base, "shear_cell", "ekm.h5"), "r") as f:
        z = f["z"][()]
    for name, rows, same in (("old-z", z[0], True), ("still-z", np.tile(z[0], (z.shape[0], 1)), False)):
        res = os.path.join(work, name)
        shutil.rmtree(res, ignore_errors=True)
        shutil.copytree(base, res, ignore=shutil.ignore_patterns("figures"))
        with h5py.File(os.path.join(res, "shear_cell", "ekm.h5"), "a") as f:
            del f["z"]
            f["z"] = rows
            f["z"].attrs["units"] = np.bytes_("m")
        rc, _, err = figures(src, res, "smoke")
        check(rc == 0, "%s: exit status %d: %s" % (name, rc, err.strip()))
        with open(os.path.join(base, "figures", "profiles_shear_cell.png"), "rb") as a, \
                open(os.path.join(res, "figures", "profiles_shear_cell.png"), "rb") as b:
            check((a.read() == b.read()) == same, "%s: profiles_shear_cell.png %s" % (
                name, "differs" if same else "is the same: the rows of /z were not used"))
    res = os.path.join(work, "bad-z")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res, ignore=shutil.ignore_patterns("figures"))  # base's figures are made
    with h5py.File(os.path.join(res, "shear_cell", "ekm.h5"), "a") as f:
        del f["z"]
        f["z"] = z[:-1]
    expect_failure(src, res, "smoke", ["shear_cell/ekm.h5", "/z", "one row of cell centres per output time"],
                   "/z with a row fewer than /t", 2)


def tmp_files(folder):
    return [f for f in os.listdir(folder) if f.endswith(".tmp")] if os.path.isdir(folder) else []


def exit_codes(src, work):
    base = os.path.join(work, "codes-base")
    synth(src, base, "ref")
    # usage: exit 1 (argparse's own status would be 2)
    rc, _, err = figures(src, base, "ref", ["--no-such-option"])
    check(rc == 1, "unknown option: exit status %d, expected 1 (%s)" % (rc, err.strip()))
    p = subprocess.run([sys.executable, os.path.join(src, "figures", "make_figures.py"), base],
                       capture_output=True, text=True)
    check(p.returncode == 1, "no --size: exit status %d, expected 1" % p.returncode)
    # a missing results folder: 3
    rc, _, err = figures(src, os.path.join(work, "no-such-folder"), "ref")
    check(rc == 3, "missing results folder: exit status %d, expected 3" % rc)
    # a Python package missing: 7 (h5py shadowed by a module that cannot be imported)
    fake = os.path.join(work, "no-h5py")
    os.makedirs(fake, exist_ok=True)
    with open(os.path.join(fake, "h5py.py"), "w") as fh:
        fh.write("raise ImportError(\"No module named 'h5py'\")\n")
    env = dict(os.environ, PYTHONPATH=fake)
    rc, _, err = figures(src, base, "ref", env=env)
    check(rc == 7 and "h5py" in err, "h5py missing: exit status %d, expected 7 (%s)" % (rc, err.strip()))
    # figures.txt cannot be written (a folder of that name): 3, no temporary left
    res = os.path.join(work, "codes-listing")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    os.makedirs(os.path.join(res, "figures", "figures.txt"))
    rc, _, err = figures(src, res, "ref")
    check(rc == 3 and "figures.txt" in err,
          "figures.txt not writable: exit status %d, expected 3 (%s)" % (rc, err.strip()))
    errors = [l for l in err.strip().splitlines() if ": note: " not in l]   # notes come before drawing
    check(len(errors) == 1, "figures.txt not writable: not one error line: %r" % err)
    left = tmp_files(os.path.join(res, "figures"))
    check(not left, "figures.txt not writable: temporaries left: %s" % left)
    # SIGTERM while drawing: 143, no temporary left
    res = os.path.join(work, "codes-term")
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    figdir = os.path.join(res, "figures")
    proc = subprocess.Popen([sys.executable, os.path.join(src, "figures", "make_figures.py"),
                             "--size", "ref", "--ekm", EKM[0], res], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    import time
    for _ in range(600):   # until the first figure is there: drawing has started
        if os.path.isdir(figdir) and any(f.endswith(".png") for f in os.listdir(figdir)):
            break
        time.sleep(0.05)
    running = proc.poll() is None
    proc.terminate()
    _, err = proc.communicate()
    check(running, "SIGTERM: make_figures.py ended (status %d) before the signal" % proc.returncode)
    check(proc.returncode == 143, "SIGTERM: exit status %d, expected 143 (%s)" % (proc.returncode, err))
    left = tmp_files(figdir)
    check(not left, "SIGTERM: temporaries left: %s" % left)
    check(not os.path.exists(os.path.join(figdir, "figures.txt")), "SIGTERM: figures.txt written")


def variant(base, work, name, change=None):
    """A copy of the results folder base (before any figures) changed by
    change(folder)."""
    res = os.path.join(work, name)
    shutil.rmtree(res, ignore_errors=True)
    shutil.copytree(base, res)
    if change:
        change(res)
    return res


def same_png(a, b, stem):
    with open(os.path.join(a, "figures", stem + ".png"), "rb") as fa, \
            open(os.path.join(b, "figures", stem + ".png"), "rb") as fb:
        return fa.read() == fb.read()


def param_sets(src, work):
    """The parameter sets: thesis (scenarios/simple_shear.ini) and every
    RES/calibration/<set>/fit.ini in the rheology figure, every
    ekm_<set>.h5 in the profiles, the train/test matrix of
    calibration.json; a set without fit.ini left out with a note; the
    closed forms are ekm homog's (the residuals of the synthetic sweep,
    whose DEM T is the thesis closed form and DEM P five times it)."""
    import json
    import numpy as np
    base = os.path.join(work, "sets-base")
    synth(src, base, "ref")
    no_fit = variant(base, work, "sets-no-fit",
                     lambda r: os.remove(os.path.join(r, "calibration", "rheology", "fit.ini")))

    def no_runs(r):
        for d, _dirs, files in os.walk(r):
            for f in files:
                if f == "ekm_rheology.h5":
                    os.remove(os.path.join(d, f))
    no_run = variant(base, work, "sets-no-run", no_runs)

    def bad_fit(r):
        with open(os.path.join(r, "calibration", "rheology", "fit.ini"), "a") as fh:
            fh.write("eps0 = 3x\n")
    bad = variant(base, work, "sets-bad-fit", bad_fit)

    def bad_cell(r):
        path = os.path.join(r, "calibration.json")
        with open(path) as fh:
            js = json.load(fh)
        del js["matrix"]["rheology"]["chute"]["train"]
        with open(path, "w") as fh:
            json.dump(js, fh)
    bad_matrix = variant(base, work, "sets-bad-matrix", bad_cell)
    no_ekm = variant(base, work, "sets-no-ekm")

    rc, _, err = figures(src, base, "ref")
    check(rc == 0, "sets: exit status %d: %s" % (rc, err.strip()))
    check("parameter set chute" in err and os.path.join("calibration", "chute", "fit.ini") in err,
          "sets: no note for the set without fit.ini (chute): %s" % err.strip())
    rc, _, err = figures(src, no_fit, "ref")
    check(rc == 0 and "parameter set rheology" in err, "sets: without rheology/fit.ini: %d %s" % (rc, err))
    check(not same_png(base, no_fit, "rheology_fit"),
          "sets: rheology_fit is the same without calibration/rheology/fit.ini (the set not drawn)")
    rc, _, err = figures(src, no_run, "ref")
    check(rc == 0, "sets: without ekm_rheology.h5: %d %s" % (rc, err))
    for stem, same in (("profiles_chute", False), ("profiles_shear_cell", False), ("profiles_filling", True)):
        check(same_png(base, no_run, stem) == same, "sets: %s.png %s without ekm_rheology.h5" % (
            stem, "differs" if same else "is the same: the rheology run was not drawn"))
    expect_failure(src, bad, "ref", ["rheology", "fit.ini", "eps0"], "a bad fit.ini", 2)
    expect_failure(src, bad_matrix, "ref", ["calibration.json", "matrix.rheology.chute", "train"],
                   "a matrix cell without train", 2)
    p = subprocess.run([sys.executable, os.path.join(src, "figures", "make_figures.py"), "--size", "ref",
                        "--ekm", os.path.join(work, "no-such-ekm"), no_ekm], capture_output=True, text=True)
    check(p.returncode == 7 and "no-such-ekm" in p.stderr and "ekm homog" in p.stderr,
          "sets: a missing ekm program: exit status %d, expected 7: %s" % (p.returncode, p.stderr.strip()))
    check(not os.path.isdir(os.path.join(no_ekm, "figures")), "sets: a missing ekm program: figures written")

    # what the figures computed, in-process
    sys.path.insert(0, os.path.join(src, "figures"))
    import common as C
    import rheology
    import calibration
    scenarios, _ = C.load_campaign(base, "ref")
    sets, _ = C.load_sets(base)
    check([s.name for s in sets] == ["thesis", "rheology"], "sets: %s" % [s.name for s in sets])
    fd = rheology.prepare(scenarios, EKM[0], src, sets)["fit"]
    check(fd is not None and len(fd.models) == 2, "sets: rheology_fit has not both sets")
    if fd is not None:
        m = C.homog(EKM[0], os.path.join(src, "scenarios", "simple_shear.ini"), sets[0],
                    (0.5, 0.5, 1), [5.0])["material"]
        n = {0: 0, 2: 0, 3: 0}
        for k, p, r in rheology.residuals(fd, fd.models[0]):
            if p.sweep != "fixed volume":
                continue
            if k == 0:   # nu = 1, phi < phi_co: mu = sqrt(3 eta0 eps0 / (2 phi)) (docs/model-notes.md section 7)
                want = np.sqrt(3 * m["eta0"] * m["eps0"] / (2 * p.phi))
                check(abs(r * p.mu_se + p.mu - want) < 1e-9 * want, "sets: thesis mu at phi %g: %g, want %g"
                      % (p.phi, r * p.mu_se + p.mu, want))
            elif k == 2:  # DEM P = 5 P_EKM (1 +- 1%), SE 3% of it: (1 - 5)/0.15
                check(abs(r + 4 / 0.15) < 1.0, "sets: thesis P residual %g, want -26.7 +- 1" % r)
            elif k == 3:  # DEM T = T_EKM (1 +- 1%), SE 3%
                check(abs(r) < 1.0, "sets: thesis T residual %g, want |r| < 1" % r)
            if k in n:
                n[k] += 1
        check(all(v == 4 for v in n.values()), "sets: residuals of the four volume-sweep points: %s" % n)
        rt = [r for k, p, r in rheology.residuals(fd, fd.models[1]) if k == 3 and p.sweep == "fixed volume"]
        check(rt and min(abs(x) for x in rt) > 1.0, "sets: the rheology set's T residuals %s: the same "
              "as the thesis set's (its fit.ini not used?)" % rt)
    data, _ = calibration.load(base)
    names, scen, rel_l2, scalar, train, present, _size = data
    check(names == ["thesis", "rheology", "chute"] and scen[3] == "simple_shear", "matrix: %s %s" % (names, scen))
    check(rel_l2[1][3] == 0.12 and train[1][3] and not train[0][3] and np.isnan(scalar[1][3])
          and np.isnan(rel_l2[0][4]) and present[0][4] and not present[2][1] and scalar[2][0] == 0.04,
          "matrix: cells not as in tests/figures/calibration.json")


def edit_options(path, change):
    """Change the "options" of a score file in place."""
    import json
    with open(path) as fh:
        js = json.load(fh)
    change(js["options"])
    with open(path, "w") as fh:
        json.dump(js, fh)


def main():
    if len(sys.argv) != 6:
        print("usage: figures_test.py SOURCE_DIR WORK CASE FIELDS_JSON EKM", file=sys.stderr)
        return 2
    src, work, case, fields, ekm = sys.argv[1:]
    FIELDS_JSON.append(fields)
    EKM.append(ekm)
    try:
        import matplotlib  # noqa: F401
        import h5py  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        print("figures_test: %s: skipped" % e)
        return 77
    os.makedirs(work, exist_ok=True)
    if case == "complete-ref":
        complete(src, work, "ref")
    elif case == "complete-smoke":
        complete(src, work, "smoke")
    elif case == "missing":
        missing(src, work)
    elif case == "failed-step":
        failed_step(src, work)
    elif case == "bad-data":
        bad_data(src, work)
    elif case == "exit-codes":
        exit_codes(src, work)
    elif case == "sets":
        param_sets(src, work)
    else:
        print("figures_test: unknown case %r" % case, file=sys.stderr)
        return 2
    if failures:
        print("figures_test %s: %d failure(s)" % (case, len(failures)), file=sys.stderr)
        return 1
    print("figures_test %s: all passed" % case)
    return 0


if __name__ == "__main__":
    sys.exit(main())
