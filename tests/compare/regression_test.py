#!/usr/bin/python3
"""regression_test.py: the committed reference results still score the same.

usage: regression_test.py EKMCOMPARE ROOT WORKDIR

For every committed results/**/score_*.json under ROOT (what `git ls-files
results` lists: the smoke campaign of `make demo` writes results/smoke/, which
is not committed and not a reference, and a user's own runs are not either;
outside a git checkout, every score file but results/smoke/'s), rerun `ekmcompare score` on the
committed inputs it names (dem, ekm) with the options recorded in it
(options.fields, options.ekm_time, options.shift_m, options.support,
options.scalars) into a temporary file under WORKDIR, and assert that
  - every field's points, points_with_se, points_left_out, rel_l2 and
    noise_normalised, the free surface (layer heights, offset) and every
    scalar (dem, dem_se, model, model_se, rel_error, error_over_se, units)
    are the committed file's, as printed (text equality of the JSON
    numbers), and the time matching and the options come out the same;
  - every row of results/scores.json that names that file has the same
    points, points_left_out, rel_l2, noise_normalised and offset_d to the
    digits printed in scores.json, and every field of every score file has
    such a row; likewise every scalar row (scalar_rows) and every scalar of
    every score file.
A change of any scoring formula, of the interpolation or of the SE floor
changes some of these numbers and fails the test.
"""
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path


def load(path):
    # numbers kept as their printed text: the comparison is to the digit
    with open(path) as fp:
        return json.load(fp, parse_float=str, parse_int=str)


def significant_digits(text):
    mantissa = text.lower().split("e")[0].lstrip("+-").replace(".", "").lstrip("0")
    return max(len(mantissa), 1)


def same_to_printed(printed, value):
    """value (full-precision text, or None for NaN) equals printed to its digits."""
    if printed is None or value is None:
        return printed is None and value is None
    d = significant_digits(printed)
    return "%.*g" % (d, float(value)) == "%.*g" % (d, float(printed))


def committed_score_files(root):
    """The committed results/**/score_*.json, relative to root."""
    git = subprocess.run(["git", "-C", str(root), "ls-files", "-z", "--", "results"],
                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    if git.returncode == 0:
        names = [n.decode() for n in git.stdout.split(b"\0") if n]
        return sorted(n for n in names if n.startswith("results/") and Path(n).name.startswith("score_")
                      and n.endswith(".json") and (root / n).is_file())
    return sorted(p.relative_to(root).as_posix() for p in root.glob("results/**/score_*.json")
                  if not p.relative_to(root).as_posix().startswith("results/smoke/"))


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: regression_test.py EKMCOMPARE ROOT WORKDIR")
    ekmc, root, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    work.mkdir(parents=True, exist_ok=True)
    fails = []
    rescored = {}  # score file (as scores.json names it) -> new fields
    rescored_scalars = {}  # score file -> new scalars
    rescored_run = {}  # score file -> its model_run (the EKM's steadiness)
    offsets = {}  # score file -> free-surface offset [d]
    files = committed_score_files(root)
    if not files:
        sys.exit(f"regression_test.py: no results/**/score_*.json under {root}")
    for rel in files:
        old = load(root / rel)
        opt = old.get("options")
        if not opt:
            fails.append(f"{rel}: no \"options\" recorded (re-score it with the current ekmcompare)")
            continue
        with tempfile.NamedTemporaryFile(dir=work, suffix=".json", delete=False) as tmp:
            out = tmp.name
        cmd = [ekmc, "score", "--dem", old["dem"], "--ekm", old["ekm"], "--fields", ",".join(opt["fields"]),
               "--ekm-time", opt["ekm_time"], "--shift", opt["shift_m"], "--support", opt["support"],
               "--scalars", ",".join(opt["scalars"]), "-o", out, "--quiet"]
        run = subprocess.run(cmd, cwd=root, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if run.returncode != 0:
            fails.append(f"{rel}: {' '.join(cmd)}: exit {run.returncode}: {run.stderr.strip()}")
            os.unlink(out)
            continue
        new = load(out)
        os.unlink(out)
        rescored[rel] = new["fields"]
        rescored_scalars[rel] = new["scalars"]
        rescored_run[rel] = new.get("model_run") or {}
        offsets[rel] = new["free_surface"].get("offset_d")
        for key in ("time", "options", "free_surface", "model_run"):
            if new.get(key) != old.get(key):
                fails.append(f"{rel}: {key}: {new.get(key)} now, committed {old.get(key)}")
        if list(new["fields"]) != list(old["fields"]):
            fails.append(f"{rel}: fields {list(new['fields'])} now, committed {list(old['fields'])}")
        for field, was in old["fields"].items():
            now = new["fields"].get(field, {})
            for k in ("points", "points_with_se", "points_left_out", "rel_l2", "noise_normalised"):
                if now.get(k) != was.get(k):
                    fails.append(f"{rel}: {field}.{k} = {now.get(k)} now, committed {was.get(k)}")
        if list(new["scalars"]) != list(old.get("scalars", {})):
            fails.append(f"{rel}: scalars {list(new['scalars'])} now, committed {list(old.get('scalars', {}))}")
        for name, was in old.get("scalars", {}).items():
            if new["scalars"].get(name) != was:
                fails.append(f"{rel}: scalar {name} = {new['scalars'].get(name)} now, committed {was}")
    table = load(root / "results" / "scores.json")
    covered = set()
    for row in table["rows"]:
        where = f"results/scores.json: {row['scenario']} {row.get('point') or ''} {row['field']}".replace("  ", " ")
        for cmp, cell in row.items():
            if isinstance(cell, dict) and cell.get("status") == "not_steady":
                # an EKM transient the table does not score: it names its file
                rel = cell.get("file")
                if rel not in rescored:
                    fails.append(f"{where} {cmp}: its file {rel} was not re-scored")
                elif rescored_run.get(rel, {}).get("steady") != "0":
                    fails.append(f"{where} {cmp}: not_steady in the table, but {rel} has model_run "
                                 f"{rescored_run.get(rel)}")
                else:
                    covered.add((rel, row["field"]))
                continue
            if isinstance(cell, dict) and cell.get("status") == "n/a" and "file" in cell:
                # a field the model does not have (T of mu_i): n/a now, for the same reason
                rel = cell["file"]
                now = rescored.get(rel, {}).get(row["field"])
                if not isinstance(now, dict) or now.get("n_a") != cell.get("reason"):
                    fails.append(f"{where} {cmp}: n/a ({cell.get('reason')}) in the table, {now} now")
                else:
                    covered.add((rel, row["field"]))
                continue
            if not isinstance(cell, dict) or cell.get("status") != "ok":
                continue
            rel = cell.get("file")
            if rel not in rescored:
                fails.append(f"{where} {cmp}: its file {rel} was not re-scored")
                continue
            now = rescored[rel].get(row["field"])
            if now is None:
                fails.append(f"{where} {cmp}: {rel} has no field {row['field']}")
                continue
            covered.add((rel, row["field"]))
            if now["points"] != cell.get("points"):
                fails.append(f"{where} {cmp}: points = {now['points']} now, {cell.get('points')} in the table")
            if now["points_left_out"] != cell.get("points_left_out"):
                fails.append(f"{where} {cmp}: points_left_out = {now['points_left_out']} now, "
                             f"{cell.get('points_left_out')} in the table")
            for k in ("rel_l2", "noise_normalised"):
                if not same_to_printed(cell.get(k), now.get(k)):
                    fails.append(f"{where} {cmp}: {k} = {now.get(k)} now, {cell.get(k)} in the table")
            if not same_to_printed(cell.get("offset_d"), offsets[rel]):
                fails.append(f"{where} {cmp}: offset_d = {offsets[rel]} now, {cell.get('offset_d')} in the table")
    covered_scalars = set()
    for row in table.get("scalar_rows", []):
        where = f"results/scores.json: {row['scenario']} {row.get('point') or ''} {row['scalar']}".replace("  ", " ")
        for cmp, cell in row.items():
            if not isinstance(cell, dict) or "file" not in cell:
                continue
            rel = cell["file"]
            if cell.get("status") == "not_steady":
                covered_scalars.add((rel, row["scalar"]))
                continue
            now = rescored_scalars.get(rel, {}).get(row["scalar"])
            if now is None:
                fails.append(f"{where} {cmp}: {rel} has no scalar {row['scalar']} now")
                continue
            covered_scalars.add((rel, row["scalar"]))
            for k in ("dem", "dem_se", "model", "model_se", "rel_error", "error_over_se"):
                if not same_to_printed(cell.get(k), now.get(k)):
                    fails.append(f"{where} {cmp}: {k} = {now.get(k)} now, {cell.get(k)} in the table")
    for rel, scalars in rescored_scalars.items():
        for name in scalars:
            if (rel, name) not in covered_scalars:
                fails.append(f"{rel}: scalar {name} has no row in results/scores.json")
    for rel, fields in rescored.items():
        for field in fields:
            if (rel, field) not in covered:
                fails.append(f"{rel}: field {field} has no row in results/scores.json")
    for f in fails:
        print(f"FAIL: {f}", file=sys.stderr)
    if fails:
        sys.exit(f"regression_test.py: {len(fails)} failure(s)")
    nf = sum(len(f) for f in rescored.values())
    ns = sum(len(f) for f in rescored_scalars.values())
    print(f"regression_test.py: {len(rescored)} score files, {nf} fields, {ns} scalars, "
          f"{len(covered)} + {len(covered_scalars)} table cells: all equal")


if __name__ == "__main__":
    main()
