#!/usr/bin/python3
"""pile_record.py: the committed records of sand-pile runs (issue 34).

    scripts/dem/pile_record.py make --law LAW --member K --from TMP [-f] -o RECORD RUN_DIR
    scripts/dem/pile_record.py mapargs RUN_DIR
    scripts/dem/pile_record.py list ROOT SIZE
    scripts/dem/pile_record.py group -o BASE.h5 [--csv BASE.csv] RECORD...
    scripts/dem/pile_record.py summary -o SUMMARY.json RECORD...
    scripts/dem/pile_record.py recover -R ROOT --summary SUMMARY.json [--commit C] BASE.h5

The runs' dumps stay on the machine that ran them (runs/pile is not
committed); a record keeps what the statistics need, a few kB, under
ROOT/<law>/<engine>-<size>/<point>/seed<k>/ (ROOT results/sandpile/runs,
law plain or rolling, point source8 the hopper or the sieve's source<W>,
k the member of scripts/dem/ensemble.sh):
  base.h5, base.csv  `ekmcompare base --last 1` of the run's atoms.dump
                     (p_base_runs [1][bins]: the pile at rest, 2 d bins
                     over the box, symmetric about its middle)
  record.json        law, engine, size, point, source (hopper: the source
                     narrower than the plate; sieve: as wide), member, the
                     run's summary row (scripts/dem/pile_summary.py: angles,
                     height, extents, base force over weight, ...), its
                     surface on the base bins (pile_stats.py's local weight:
                     h per bin, floor grains per bin, the pile's mass, the
                     box's y period), where the run was and when recorded;
                     "recovered_from" when it was rebuilt from a group file;
                     "map" when the record has map.h5
  map.h5             the pile at rest on a 2D grid (pile_map.py: `ekmcompare
                     cg --axes x,z` of the run's last snapshot, 2 d cells
                     over the box's x period and from the plate's top to the
                     box's top; phi, cxx, czz, cxz with units, gzip), about
                     20 kB; absent in records made before the maps and in
                     recovered records
  run.json, vars.txt the run's own (absent in a recovered record)

make: TMP, a new directory beside RECORD, holds base.h5 and base.csv of
the run and cg.h5 (pile_record.sh writes them with ekmcompare: cg.h5 is
`ekmcompare cg` with the options of mapargs); make turns cg.h5 into
TMP/map.h5 (and removes cg.h5 and its cg.xdmf), writes TMP/record.json, copies run.json and vars.txt, checks the record against
the place RECORD (as list does) and renames TMP to RECORD; an existing
RECORD is refused (2) unless -f (then replaced). LAW must agree with
vars.txt (plain: mu_r = 0, rolling: mu_r > 0).
mapargs: the options of `ekmcompare cg` for the run's map, one a line
(pile_map.py cg_args: the grid from vars.txt, the last step of atoms.dump).
list: every record of size SIZE under ROOT, checked (the checks of group
below, one record at a time), one line each: law engine source point
member dir, in the order law, engine, source, member.
group: the records of one group in the layout of `ekmcompare base` (x,
p_base, p_base_se, p_base_se_fold, p_base_runs, the same attributes; inputs
names the records; snapshots_read only when every record has it) and, when
every record has its surface, h_runs, floor_grains_runs [runs][bins] and
pile_mass_runs [runs] (pile_stats.py reads them instead of dumps). The
records must share the grid, the engine, size, law and point, and (those
with vars.txt) every deck variable but the seeds, the output intervals and
the settling's end (settle_max, rest_ke), and those with map.h5 its grid.
summary: pile_summary.py's table (per law: groups by engine, size and
point, mean and SE over the runs) of the records' summary rows; a row's
"run" is its record's path relative to the records' common root.
recover: the records of a group file written by the earlier pile_analysis.sh
(from dumps): its p_base_runs row i is run i of its inputs, whose summary
row is taken from SUMMARY.json (pile_summary.py --runs over the same runs);
the row must match (engine, size, point, the floor load of the profile
equal to the row's base force to 1e-9), else nothing is written. Such a
record has no surface, run.json nor vars.txt (they were not kept), and
names the files it came from (and --commit, the commit that holds them). An
existing record is left as it is.

Outputs are written to a temporary name and renamed. Exit status
(docs/exit-codes.md): 0 ok; 1 usage; 2 bad input (one line naming the
file and what was expected: a record.json, base.h5 or map.h5 not as
described, a record whose place disagrees with its content, records that do not pool,
a summary row that does not match); 3 a file missing or not writable; 7
h5py or numpy missing.
"""
import datetime
import glob
import json
import os
import re
import shutil
import sys

PROG = "pile_record"
FORMAT = "ekmbench sand-pile run record 1"
LAWS = ("plain", "rolling")
ENGINES = ("lammps", "liggghts")
SOURCES = ("hopper", "sieve")
# deck variables that may differ within a group: each member's seeds, the
# output intervals (they do not change the pile), and the settling's end
# (settle_max, rest_ke: how long a pile still moving at t_end runs on; a
# recorded pile is at rest, and one at rest at t_end is the same run
# whatever they are; records made before the settling have neither)
FREE_VARS = ("seed", "seed2", "seed3", "thermo_every", "dump_every", "settle_max", "rest_ke")
SUMMARY_KEYS = ("engine", "size", "point", "seed", "mass", "weight", "base_force", "base_over_weight",
                "angle_left", "angle_right", "angle", "height", "toe_left", "toe_right", "toe_margin",
                "strays", "p_centre_over_max", "wall_time_s")
np = h5py = None  # imported in main (a clear message without them)


class Fail(Exception):
    def __init__(self, code, msg):
        super().__init__(msg)
        self.code = code


def die(code, msg):
    raise Fail(code, msg)


def bstr(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def write_atomic(path, writer):
    d = os.path.dirname(os.path.abspath(path))
    tmp = os.path.join(d, ".%s.tmp%d" % (os.path.basename(path), os.getpid()))
    try:
        writer(tmp)
        os.replace(tmp, path)
    except OSError as e:
        if os.path.exists(tmp):
            os.unlink(tmp)
        die(3, "%s: cannot write (%s)" % (path, e.strerror or e))


def write_json(path, doc):
    def w(t):
        with open(t, "w") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")
    write_atomic(path, w)


# ------------------------------------------------------------ base files
def read_base_h5(path):
    """{x, runs [R][n], attrs} of an ekmcompare base HDF5 (or a record's)."""
    if not os.path.exists(path):
        die(3, "%s: no such file" % path)
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        die(2, "%s: expected an HDF5 file of ekmcompare base (%s)" % (path, e))
    with f:
        for name in ("x", "p_base_runs"):
            if name not in f:
                die(2, "%s: no dataset %s (expected the output of ekmcompare base)" % (path, name))
        for a in ("dx", "lo", "hi", "centre", "y_period"):
            if a not in f.attrs:
                die(2, "%s: no attribute %s (expected the output of ekmcompare base)" % (path, a))
        x = np.asarray(f["x"][...], dtype=float)
        runs = np.asarray(f["p_base_runs"][...], dtype=float)
        attrs = {k: (bstr(v) if isinstance(v, (bytes, str)) else float(v)) for k, v in f.attrs.items()}
    if x.ndim != 1 or runs.ndim != 2 or runs.shape[1] != x.size:
        die(2, "%s: p_base_runs: expected [runs][%d bins], got shape %s" % (path, x.size, runs.shape))
    return {"x": x, "runs": runs, "attrs": attrs}


def base_arrays(runs):
    """p_base, p_base_se, p_base_se_fold of p_base_runs, as ekmcompare base computes them."""
    R = runs.shape[0]
    p = runs.mean(axis=0)
    se = runs.std(axis=0, ddof=1) / np.sqrt(R) if R >= 2 else np.full(runs.shape[1], np.nan)
    return p, se, 0.5 * np.abs(p - p[::-1])


def write_base(path, csv, x, runs, sattrs, nattrs, extra=()):
    """An HDF5 (and CSV) in the layout of `ekmcompare base`; extra: (name, data, units)."""
    p, se, fold = base_arrays(runs)

    def wh5(t):
        with h5py.File(t, "w") as f:
            for name, data, units in (("x", x, "m"), ("p_base", p, "Pa"), ("p_base_se", se, "Pa"),
                                      ("p_base_se_fold", fold, "Pa"), ("p_base_runs", runs, "Pa")) + tuple(extra):
                ds = f.create_dataset(name, data=np.asarray(data, dtype=float))
                ds.attrs["units"] = np.bytes_(units)
            for k, v in sattrs:
                f.attrs[k] = np.bytes_(v)
            for k, v in nattrs:
                f.attrs[k] = float(v)

    def wcsv(t):
        with open(t, "w") as f:
            f.write("x,p_base,p_base_se,p_base_se_fold\n")
            for k in range(x.size):
                f.write("%.9g,%.9g,%.9g,%.9g\n" % (x[k], p[k], se[k], fold[k]))

    if path:
        write_atomic(path, wh5)
    if csv:
        try:
            write_atomic(csv, wcsv)
        except Fail:
            if path and os.path.exists(path):
                os.unlink(path)
            raise


STD_STRINGS = {
    "axis": "x",
    "quantity": "base pressure -sum(fz of the floor grains in a bin)/(dx y_period)",
    "standard_error": "p_base_se: across the runs, sd/sqrt(runs); p_base_se_fold: |p(x) - p(2 centre - x)|/2",
}


# --------------------------------------------------------------- records
def read_vars_file(path):
    out = {}
    with open(path) as f:
        for line in f:
            k, eq, v = line.partition("=")
            if eq:
                out[k.strip()] = v.strip()
    return out


def place_of(rec):
    """(law, engine-size, point, seed<k>) of a record's directory."""
    parts = os.path.normpath(os.path.abspath(rec)).split(os.sep)
    return parts[-4:]


def load_record(rec, place=None):
    """A record's content, checked against its place (rec, or place for a
    record still in its temporary directory) and its base.h5."""
    rj = os.path.join(rec, "record.json")
    if not os.path.isfile(rj):
        die(3, "%s: no such file (expected a run record: record.json, base.h5)" % rj)
    try:
        with open(rj) as f:
            doc = json.load(f)
    except (ValueError, UnicodeDecodeError) as e:
        die(2, "%s: expected JSON (a run record), got: %s" % (rj, e))
    except OSError as e:
        die(3, "%s: cannot read (%s)" % (rj, e.strerror))
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        die(2, "%s: expected \"format\": \"%s\"" % (rj, FORMAT))
    kinds = (("law", str), ("engine", str), ("size", str), ("point", str), ("source", str), ("member", int),
             ("summary", dict))
    for k, t in kinds:
        if not isinstance(doc.get(k), t) or isinstance(doc.get(k), bool):
            die(2, "%s: expected \"%s\" (%s)" % (rj, k, "an integer" if t is int else
                                                  "an object" if t is dict else "a string"))
    if doc["law"] not in LAWS or doc["engine"] not in ENGINES or doc["source"] not in SOURCES:
        die(2, "%s: expected law %s, engine %s and source %s, got %s, %s, %s"
            % (rj, "/".join(LAWS), "/".join(ENGINES), "/".join(SOURCES), doc["law"], doc["engine"], doc["source"]))
    want = [doc["law"], "%s-%s" % (doc["engine"], doc["size"]), doc["point"], "seed%d" % doc["member"]]
    where = place_of(place or rec)
    if where != want:
        die(2, "%s: the record is of %s but %s in %s (expected <law>/<engine>-<size>/<point>/seed<k>)"
            % (rj, "/".join(want), "goes" if place else "lies", "/".join(where)))
    for k in SUMMARY_KEYS:
        if k not in doc["summary"]:
            die(2, "%s: summary: no \"%s\" (expected pile_summary.py's row)" % (rj, k))
    s = doc["summary"]
    if (s["engine"], s["size"], s["point"]) != (doc["engine"], doc["size"], doc["point"]):
        die(2, "%s: summary: engine, size, point %s, %s, %s, expected the record's %s, %s, %s"
            % (rj, s["engine"], s["size"], s["point"], doc["engine"], doc["size"], doc["point"]))
    bpath = os.path.join(rec, "base.h5")
    base = read_base_h5(bpath)
    if base["runs"].shape[0] != 1:
        die(2, "%s: p_base_runs: expected one run (a run record), got %d" % (bpath, base["runs"].shape[0]))
    n = base["x"].size
    surf = doc.get("surface")
    if surf is not None:
        ok = isinstance(surf, dict) and all(isinstance(surf.get(k), list) and len(surf[k]) == n
                                            for k in ("h", "floor_grains"))
        ok = ok and all(isinstance(surf.get(k), (int, float)) and not isinstance(surf.get(k), bool)
                        for k in ("pile_mass", "y_period"))
        if not ok:
            die(2, "%s: surface: expected h and floor_grains (%d numbers each, the base bins), pile_mass, y_period"
                % (rj, n))
        try:
            surf = {"h": np.array(surf["h"], dtype=float), "floor_grains": np.array(surf["floor_grains"], dtype=float),
                    "pile_mass": float(surf["pile_mass"]), "y_period": float(surf["y_period"])}
        except (TypeError, ValueError):
            die(2, "%s: surface: expected numbers" % rj)
    rec_from = doc.get("recovered_from")
    variables = None
    if rec_from is None:
        for f in ("run.json", "vars.txt"):
            if not os.path.isfile(os.path.join(rec, f)):
                die(3, "%s: no such file (a record not recovered keeps its run's %s)" % (os.path.join(rec, f), f))
        variables = read_vars_file(os.path.join(rec, "vars.txt"))
        try:
            with open(os.path.join(rec, "run.json")) as f:
                status = json.load(f).get("status")
        except (ValueError, UnicodeDecodeError, AttributeError):
            die(2, "%s: expected the run's run.json (JSON)" % os.path.join(rec, "run.json"))
        if status != "ok":
            die(2, "%s: status %s, expected ok (a record keeps a finished run)" % (os.path.join(rec, "run.json"), status))
    mpath = os.path.join(rec, "map.h5")
    pmap = None
    if os.path.exists(mpath) or doc.get("map") is not None:
        import pile_map
        try:
            pmap = pile_map.read_map(mpath)
        except pile_map.MapError as e:
            die(e.code, str(e))
    return {"dir": rec, "doc": doc, "base": base, "surface": surf, "vars": variables, "json": rj, "map": pmap}


def pool(recs):
    """Check that records form one group: the same grid, engine, size, law, point and deck variables."""
    first = recs[0]
    b0 = first["base"]
    key0 = tuple(first["doc"][k] for k in ("law", "engine", "size", "point"))
    vfirst = next((r for r in recs if r["vars"] is not None), None)
    for r in recs:
        key = tuple(r["doc"][k] for k in ("law", "engine", "size", "point"))
        if key != key0:
            die(2, "%s: a record of %s, expected %s as %s (one group)" % (r["json"], "/".join(key), "/".join(key0),
                                                                          first["json"]))
        b = r["base"]
        bp = os.path.join(r["dir"], "base.h5")
        if b["x"].size != b0["x"].size or not np.allclose(b["x"], b0["x"], rtol=0, atol=1e-9 * b0["attrs"]["dx"]):
            die(2, "%s: a grid of %d bins %g .. %g m, expected that of %s (%d bins %g .. %g m)"
                % (bp, b["x"].size, b["attrs"]["lo"], b["attrs"]["hi"], os.path.join(first["dir"], "base.h5"),
                   b0["x"].size, b0["attrs"]["lo"], b0["attrs"]["hi"]))
        for a in ("dx", "centre", "y_period"):
            if abs(b["attrs"][a] - b0["attrs"][a]) > 1e-9 * abs(b0["attrs"][a]):
                die(2, "%s: %s %g, expected that of %s (%g)" % (bp, a, b["attrs"][a],
                                                                 os.path.join(first["dir"], "base.h5"), b0["attrs"][a]))
        if r["map"] is not None:
            import pile_map
            m0 = next(q for q in recs if q["map"] is not None)
            try:
                pile_map.same_grid([m0["map"], r["map"]], [os.path.join(m0["dir"], "map.h5"),
                                                           os.path.join(r["dir"], "map.h5")])
            except pile_map.MapError as e:
                die(e.code, str(e))
        if r["vars"] is not None and vfirst is not None:
            v0 = vfirst["vars"]
            for k in sorted(set(r["vars"]) | set(v0)):
                if k not in FREE_VARS and r["vars"].get(k) != v0.get(k):
                    die(2, "%s: %s = %s, expected %s as in %s (runs of one group share the deck but the seeds)"
                        % (os.path.join(r["dir"], "vars.txt"), k, r["vars"].get(k), v0.get(k),
                           os.path.join(vfirst["dir"], "vars.txt")))


# ----------------------------------------------------------- subcommands
def cmd_make(args):
    import pile_stats
    import pile_summary
    run, out = args.run, args.tmp
    if os.path.exists(args.out) and not args.force:
        die(2, "%s: exists (a record is kept; -f replaces it)" % args.out)
    for f in ("run.json", "vars.txt", "atoms.dump"):
        if not os.path.isfile(os.path.join(run, f)):
            die(3, "%s: no such file (a finished run of scripts/dem/run.sh sandpile)" % os.path.join(run, f))
    bpath = os.path.join(out, "base.h5")
    base = read_base_h5(bpath)
    if base["runs"].shape[0] != 1:
        die(2, "%s: p_base_runs: expected one run, got %d" % (bpath, base["runs"].shape[0]))
    try:
        with open(os.path.join(run, "run.json")) as f:
            rj = json.load(f)
        if not isinstance(rj, dict):
            raise ValueError("not an object")
    except (ValueError, UnicodeDecodeError) as e:
        die(2, "%s: expected the run's JSON record (%s)" % (os.path.join(run, "run.json"), e))
    for k in ("engine", "size", "point"):
        if not isinstance(rj.get(k), str) or not rj[k]:
            die(2, "%s: expected \"%s\" (run.sh's run.json)" % (os.path.join(run, "run.json"), k))
    if rj.get("status") != "ok" or rj.get("scenario") != "sandpile":
        die(2, "%s: expected a finished sandpile run (status ok), got %s %s"
            % (os.path.join(run, "run.json"), rj.get("scenario"), rj.get("status")))
    v = pile_dump_vars(run)
    for k in ("mu_r", "source_width", "lp", "d"):
        if k not in v:
            die(2, "%s: no %s (expected the sand-pile deck's variables)" % (os.path.join(run, "vars.txt"), k))
    if (args.law == "plain") != (v["mu_r"] == 0):
        die(2, "%s: mu_r = %g, expected %s for the law %s" % (os.path.join(run, "vars.txt"), v["mu_r"],
                                                            "0" if args.law == "plain" else "> 0", args.law))
    source = "sieve" if v["source_width"] * v["d"] >= v["lp"] - 1e-9 * v["d"] else "hopper"
    row = pile_summary.summarise(run)
    x, dx = base["x"], base["attrs"]["dx"]
    try:
        h, nfl, mass, ly = pile_stats.heights(os.path.join(run, "atoms.dump"), x, dx)
    except pile_stats.Fail as e:
        die(e.code, str(e))
    doc = {
        "format": FORMAT, "law": args.law, "engine": rj["engine"], "size": rj["size"], "point": rj["point"],
        "source": source, "member": args.member, "run_dir": os.path.abspath(run),
        "recorded": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "check": "scripts/dem/check_run.sh --sandpile passed (pile_record.sh)",
        "summary": row,
        "surface": {"definition": "per base bin (base.h5 x): h the highest z + radius of the pile grains "
                                  "(type 1, on the plate), floor_grains the floor grains (type 2) of the last "
                                  "frame; pile_mass the mass of the pile grains on the plate [kg]; y_period [m]",
                    "h": [float(a) for a in h], "floor_grains": [int(a) for a in nfl],
                    "pile_mass": mass, "y_period": ly},
        "recovered_from": None,
        "map": None,
    }
    cg = os.path.join(out, "cg.h5")
    if os.path.exists(cg):
        import pile_map
        try:
            pile_map.write_map(cg, os.path.join(out, "map.h5"), v["d"])
        except pile_map.MapError as e:
            die(e.code, str(e))
        for f in (cg, os.path.join(out, "cg.xdmf")):
            if os.path.exists(f):
                os.unlink(f)
        doc["map"] = {"file": "map.h5", "definition": "ekmcompare cg --axes x,z of the run's last snapshot: the "
                      "pile grains (type 1), gauss kernel of sd d, 2 d cells over the box's x period and from "
                      "the plate's top (z = 0) to the box's top; phi [1] and the contact stress cxx czz cxz [Pa] "
                      "of the per-atom c_sa (negative in compression), [nz][nx] (scripts/dem/pile_map.py)"}
    for f in ("run.json", "vars.txt"):
        try:
            shutil.copyfile(os.path.join(run, f), os.path.join(out, f))
        except OSError as e:
            die(3, "%s: cannot write (%s)" % (os.path.join(out, f), e.strerror))
    write_json(os.path.join(out, "record.json"), doc)
    load_record(out, place=args.out)
    old = None
    try:
        if os.path.exists(args.out):
            old = "%s.old%d" % (os.path.join(os.path.dirname(args.out), "." + os.path.basename(args.out)), os.getpid())
            os.rename(args.out, old)
        os.rename(out, args.out)
    except OSError as e:
        if old and not os.path.exists(args.out):
            os.rename(old, args.out)
        die(3, "%s: cannot rename %s to it (%s)" % (args.out, out, e.strerror))
    if old:
        shutil.rmtree(old, ignore_errors=True)


def cmd_mapargs(args):
    import pile_map
    try:
        print("\n".join(pile_map.cg_args(args.run)))
    except pile_map.MapError as e:
        die(e.code, str(e))


def pile_dump_vars(run):
    import pile_dump
    try:
        return pile_dump.read_vars(run)
    except pile_dump.DumpError as e:
        die(e.code, str(e))


def find_records(root, size):
    recs = []
    pat = os.path.join(glob.escape(root), "*", "*-" + glob.escape(size), "*", "seed*")
    for d in sorted(glob.glob(pat)):
        if os.path.isdir(d) and re.fullmatch(r"seed[1-9][0-9]*", os.path.basename(d)):
            recs.append(d)
    return recs


def cmd_list(args):
    if not os.path.isdir(args.root):
        die(3, "%s: no such directory (the records' root, results/sandpile/runs)" % args.root)
    recs = [load_record(d) for d in find_records(args.root, args.size)]
    groups = {}
    for r in recs:
        d = r["doc"]
        groups.setdefault((d["law"], d["engine"], d["source"]), []).append(r)
    for key in sorted(groups):
        rs = sorted(groups[key], key=lambda r: (r["doc"]["point"], r["doc"]["member"]))
        points = sorted({r["doc"]["point"] for r in rs})
        if len(points) > 1:
            die(2, "%s: source %s of point %s, and %s of point %s: one source, one point"
                % (rs[-1]["json"], key[2], points[-1], rs[0]["json"], points[0]))
        pool(rs)
        for r in rs:
            d = r["doc"]
            print("%s %s %s %s %d %s" % (d["law"], d["engine"], d["source"], d["point"], d["member"], r["dir"]))


def cmd_group(args):
    recs = [load_record(d) for d in args.records]
    pool(recs)
    runs = np.concatenate([r["base"]["runs"] for r in recs])
    b0 = recs[0]["base"]
    a0 = b0["attrs"]
    versions = []
    for r in recs:
        v = r["base"]["attrs"].get("code_version", "unknown")
        if v not in versions:
            versions.append(v)
    recovered = [r["dir"] for r in recs if r["doc"].get("recovered_from") is not None]
    sattrs = [("inputs", "\n".join(r["dir"] for r in recs)), ("axis", STD_STRINGS["axis"]),
              ("quantity", STD_STRINGS["quantity"]), ("floor_type", a0.get("floor_type", "2")),
              ("window", "%d run records, each the last snapshot of its run (ekmcompare base --last 1)" % len(recs)),
              ("standard_error", STD_STRINGS["standard_error"]), ("code_version", ", ".join(versions)),
              ("assembled", "scripts/dem/pile_record.py group: p_base_runs row i is inputs' record i"),
              ("recovered", "\n".join(recovered))]
    nattrs = [("dx", a0["dx"]), ("lo", a0["lo"]), ("hi", a0["hi"]), ("centre", a0["centre"]),
              ("y_period", a0["y_period"]),
              ("floor_load", float(np.mean([r["base"]["attrs"].get("floor_load", np.nan) for r in recs]))),
              ("floor_grains", a0.get("floor_grains", np.nan)), ("runs", len(recs))]
    if all("snapshots_read" in r["base"]["attrs"] for r in recs):
        nattrs.append(("snapshots_read", sum(r["base"]["attrs"]["snapshots_read"] for r in recs)))
    nattrs += [("snapshots_used", sum(r["base"]["attrs"].get("snapshots_used", 1.0) for r in recs)),
               ("floor_grains_outside_grid", sum(r["base"]["attrs"].get("floor_grains_outside_grid", 0.0)
                                                 for r in recs))]
    extra = ()
    if all(r["surface"] is not None for r in recs):
        for r in recs:
            if abs(r["surface"]["y_period"] - a0["y_period"]) > 1e-9 * a0["y_period"]:
                die(2, "%s: surface: y_period %g, expected its base.h5's %g" % (r["json"], r["surface"]["y_period"],
                                                                                 a0["y_period"]))
        extra = (("h_runs", np.array([r["surface"]["h"] for r in recs]), "m"),
                 ("floor_grains_runs", np.array([r["surface"]["floor_grains"] for r in recs]), "1"),
                 ("pile_mass_runs", np.array([r["surface"]["pile_mass"] for r in recs]), "kg"))
    write_base(args.out, args.csv, b0["x"], runs, sattrs, nattrs, extra)
    print("%s: %d records -> %s%s" % (PROG, len(recs), args.out or args.csv,
                                      "" if extra else " (no surface: %d recovered)" % len(recovered)),
          file=sys.stderr)


def cmd_summary(args):
    import pile_summary
    recs = [load_record(d) for d in args.records]
    root = os.path.commonpath([os.path.abspath(r["dir"]) for r in recs])
    if len(recs) == 1:
        root = os.path.dirname(root)
    rows = []
    for r in recs:
        row = dict(r["doc"]["summary"])
        row["run"] = os.path.abspath(r["dir"])
        rows.append(row)
    pile_summary.write_table(rows, root, args.out)  # its errors: its own line and status


def cmd_recover(args):
    base = read_base_h5(args.base)
    name = os.path.basename(args.base)
    m = re.fullmatch(r"base-(plain|rolling)-(lammps|liggghts)-(hopper|sieve)-([A-Za-z0-9_]+)\.h5", name)
    if not m:
        die(2, "%s: expected a group file base-<law>-<engine>-<source>-<size>.h5 of pile_analysis.sh" % args.base)
    law, engine, source, size = m.groups()
    inputs = [s for s in base["attrs"].get("inputs", "").split("\n") if s]
    R, n = base["runs"].shape
    if len(inputs) != R:
        die(2, "%s: inputs names %d dumps for %d runs (expected one per p_base_runs row)" % (args.base, len(inputs), R))
    try:
        with open(args.summary) as f:
            summ = json.load(f)
        sroot, rows = summ["root"], summ["runs"]
    except OSError as e:
        die(3, "%s: cannot read (%s)" % (args.summary, e.strerror))
    except (ValueError, KeyError, TypeError):
        die(2, "%s: expected pile_summary.py's table (root, runs)" % args.summary)
    a = base["attrs"]
    dx, ly = a["dx"], a["y_period"]
    for i, dump in enumerate(inputs):
        mi = re.search(r"(?:^|/)(plain|rolling)/seed([1-9][0-9]*)/sandpile/(lammps|liggghts)-([A-Za-z0-9_]+)/"
                       r"(source[0-9]+)/atoms\.dump$", dump)
        if not mi or mi.group(1) != law or mi.group(3) != engine or mi.group(4) != size:
            die(2, "%s: inputs line %d '%s': expected .../%s/seed<k>/sandpile/%s-%s/<point>/atoms.dump"
                % (args.base, i + 1, dump, law, engine, size))
        k, point = int(mi.group(2)), mi.group(5)
        rel = "seed%d/sandpile/%s-%s/%s" % (k, engine, size, point)
        match = [r for r in rows if isinstance(r, dict) and r.get("run") == rel
                 and os.path.basename(os.path.normpath(sroot)) == law]
        if len(match) != 1:
            die(2, "%s: expected one row of run %s (law %s) for %s inputs line %d, got %d"
                % (args.summary, rel, law, args.base, i + 1, len(match)))
        row = dict(match[0])
        p = base["runs"][i]
        fin = np.isfinite(p)
        load = float(np.sum(p[fin]) * dx * ly)
        force = row.get("base_force")
        if (row.get("engine"), row.get("size"), row.get("point"), row.get("status")) != (engine, size, point, "ok") \
                or not isinstance(force, (int, float)) or not abs(load - force) <= 1e-9 * abs(load):
            die(2, "%s: the row of run %s does not match p_base_runs row %d of %s (engine, size, point, status ok, "
                "floor load %.9g N against the row's base_force %s)"
                % (args.summary, rel, i, args.base, load, force))
        rec = os.path.join(args.root, law, "%s-%s" % (engine, size), point, "seed%d" % k)
        if os.path.exists(rec):
            print("%s: %s exists: left as it is" % (PROG, rec), file=sys.stderr)
            continue
        row["run"] = os.path.join(sroot, rel)
        where = "%s (p_base_runs row %d)" % (args.base, i)
        src = {"base": args.base, "row": i, "summary": args.summary, "commit": args.commit,
               "note": "the run's dumps were lost with the machine (docs/dem.md Status); the profile is the "
                       "group file's row for this run (ekmcompare base --last 1, the same grid), the summary "
                       "row pile_summary.py's of the same run; the surface per bin, run.json and vars.txt were "
                       "not kept"}
        doc = {"format": FORMAT, "law": law, "engine": engine, "size": size, "point": point, "source": source,
               "member": k, "run_dir": row["run"],
               "recorded": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
               "check": "scripts/dem/check_run.sh --sandpile passed (pile_analysis.sh kept only such runs)",
               "summary": row, "surface": None, "recovered_from": src}
        parent = os.path.dirname(rec)
        try:
            os.makedirs(parent, exist_ok=True)
        except OSError as e:
            die(3, "%s: cannot create (%s)" % (parent, e.strerror))
        tmp = os.path.join(parent, ".seed%d.tmp%d" % (k, os.getpid()))
        try:
            os.mkdir(tmp)
            sattrs = [("inputs", dump), ("axis", STD_STRINGS["axis"]), ("quantity", STD_STRINGS["quantity"]),
                      ("floor_type", a.get("floor_type", "2")),
                      ("window", "the last snapshot, step %s (the summary row's): recovered from %s, whose window "
                                 "was '%s'" % (row.get("step"), where, a.get("window", ""))),
                      ("standard_error", STD_STRINGS["standard_error"]),
                      ("code_version", a.get("code_version", "unknown")),
                      ("recovered_from", where + (", commit %s" % args.commit if args.commit else ""))]
            nattrs = [("dx", dx), ("lo", a["lo"]), ("hi", a["hi"]), ("centre", a["centre"]), ("y_period", ly),
                      ("floor_load", load), ("floor_grains", row.get("n_floor", np.nan)), ("runs", 1),
                      ("snapshots_used", 1), ("floor_grains_outside_grid", a.get("floor_grains_outside_grid", 0.0))]
            write_base(os.path.join(tmp, "base.h5"), os.path.join(tmp, "base.csv"), base["x"], p[None, :],
                       sattrs, nattrs)
            write_json(os.path.join(tmp, "record.json"), doc)
            os.rename(tmp, rec)
        except OSError as e:
            shutil.rmtree(tmp, ignore_errors=True)
            die(3, "%s: cannot write (%s)" % (rec, e.strerror))
        except Fail:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
        load_record(rec)
        print("%s: %s <- %s" % (PROG, rec, where), file=sys.stderr)


def main(argv):
    import argparse
    ap = argparse.ArgumentParser(prog=PROG, description="records of sand-pile runs (issue 34)")
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("make")
    p.add_argument("--law", required=True, choices=LAWS)
    p.add_argument("--member", required=True, type=int)
    p.add_argument("--from", dest="tmp", required=True, metavar="TMP")
    p.add_argument("-f", dest="force", action="store_true")
    p.add_argument("-o", dest="out", required=True, metavar="RECORD")
    p.add_argument("run", metavar="RUN_DIR")
    p = sub.add_parser("mapargs")
    p.add_argument("run", metavar="RUN_DIR")
    p = sub.add_parser("list")
    p.add_argument("root", metavar="ROOT")
    p.add_argument("size", metavar="SIZE")
    p = sub.add_parser("group")
    p.add_argument("-o", dest="out", metavar="BASE.h5")
    p.add_argument("--csv", metavar="BASE.csv")
    p.add_argument("records", nargs="+", metavar="RECORD")
    p = sub.add_parser("summary")
    p.add_argument("-o", dest="out", required=True, metavar="SUMMARY.json")
    p.add_argument("records", nargs="+", metavar="RECORD")
    p = sub.add_parser("recover")
    p.add_argument("-R", dest="root", required=True, metavar="ROOT")
    p.add_argument("--summary", required=True, metavar="SUMMARY.json")
    p.add_argument("--commit", metavar="C")
    p.add_argument("base", metavar="BASE.h5")
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:
        return 1 if e.code else 0
    if args.cmd == "make" and args.member < 1:
        print("%s: --member: expected k >= 1, got %d" % (PROG, args.member), file=sys.stderr)
        return 1
    if args.cmd == "group" and not (args.out or args.csv):
        print("%s: group: expected -o BASE.h5 and/or --csv BASE.csv" % PROG, file=sys.stderr)
        return 1
    global np, h5py
    try:
        import numpy
        import h5py as h5
    except ImportError as e:
        print("%s: %s: run with /usr/bin/python3 (Debian's python3-numpy, python3-h5py)" % (PROG, e), file=sys.stderr)
        return 7
    np, h5py = numpy, h5
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    try:
        {"make": cmd_make, "mapargs": cmd_mapargs, "list": cmd_list, "group": cmd_group, "summary": cmd_summary,
         "recover": cmd_recover}[args.cmd](args)
    except Fail as e:
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return e.code
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
