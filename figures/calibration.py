"""calibration.py: the train/test matrix of the calibration as a heat map
(calibration_matrix), from RES/calibration.json (made by the campaign's
calibration step): rows the parameter sets, columns the scenarios; a
cell's colour is its rel_l2 (the mean relative L2 error over phi, u, P, T
on the common support; grey where there is none), its text rel_l2 and
scalar_rel (the mean |relative error| of the scenario's scalars; "-" when
there are none); the cells a set was trained on are outlined and marked
"train". No calibration.json: no figure, with a note.
"""
import os

import numpy as np

import common as C

STEM = "calibration_matrix"


def _num_or_none(v, where):
    if v is None:
        return np.nan
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or v < 0:
        raise C.InputError("%s: expected a number >= 0 or null, got %r" % (where, v))
    return float(v)


def load(res):
    """(sets, scenarios, rel_l2 [set][scenario], scalar_rel, train) of
    RES/calibration.json, checked; None (and a note) when it is absent."""
    path = os.path.join(res, "calibration.json")
    if not os.path.isfile(path):
        return None, ["%s: missing: no train/test matrix" % C.rel(path)]
    js = C.read_json(path, "the calibration's train/test matrix")
    where = C.rel(path)
    if not isinstance(js, dict):
        raise C.InputError("%s: expected an object (the calibration summary)" % where)
    sets = js.get("sets")
    if not isinstance(sets, list) or not sets or not all(
            isinstance(s, dict) and isinstance(s.get("name"), str) for s in sets):
        raise C.InputError("%s: 'sets': expected a non-empty list of objects with a 'name'" % where)
    scen = js.get("scenarios")
    if not isinstance(scen, list) or not scen or not all(isinstance(s, str) for s in scen):
        raise C.InputError("%s: 'scenarios': expected a non-empty list of names" % where)
    matrix = js.get("matrix")
    if not isinstance(matrix, dict):
        raise C.InputError("%s: 'matrix': expected an object {set: {scenario: cell}}" % where)
    names = [s["name"] for s in sets]
    rel_l2 = np.full((len(names), len(scen)), np.nan)
    scalar = np.full_like(rel_l2, np.nan)
    train = np.zeros(rel_l2.shape, dtype=bool)
    present = np.zeros(rel_l2.shape, dtype=bool)
    for i, n in enumerate(names):
        row = matrix.get(n, {})
        if not isinstance(row, dict):
            raise C.InputError("%s: 'matrix.%s': expected an object {scenario: cell}" % (where, n))
        for j, s in enumerate(scen):
            cell = row.get(s)
            if cell is None:
                continue
            w = "%s: 'matrix.%s.%s" % (where, n, s)
            if not isinstance(cell, dict) or "rel_l2" not in cell or "scalar_rel" not in cell \
                    or not isinstance(cell.get("train"), bool):
                raise C.InputError("%s': expected an object with rel_l2, scalar_rel and train (a boolean)" % w)
            rel_l2[i, j] = _num_or_none(cell["rel_l2"], w + ".rel_l2'")
            scalar[i, j] = _num_or_none(cell["scalar_rel"], w + ".scalar_rel'")
            train[i, j] = cell["train"]
            present[i, j] = True
    return (names, scen, rel_l2, scalar, train, present, js.get("size")), []


def make(data, writer):
    if data is None:
        return []
    names, scen, rel_l2, scalar, train, present, _size = data
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle
    ns, nc = len(names), len(scen)
    fig, ax = plt.subplots(figsize=(min(C.PAGE_W, 1.6 + 1.05 * nc), 0.9 + 0.45 * ns))
    cmap = plt.get_cmap("viridis").copy()
    cmap.set_bad("0.85")
    finite = rel_l2[np.isfinite(rel_l2)]
    vmax = float(finite.max()) if finite.size and finite.max() > 0 else 1.0
    im = ax.imshow(np.ma.masked_invalid(rel_l2), cmap=cmap, vmin=0.0, vmax=vmax, aspect="auto")
    for i in range(ns):
        for j in range(nc):
            if not present[i, j]:
                txt, bright = "n/a", True
            else:
                r = "%.3g" % rel_l2[i, j] if np.isfinite(rel_l2[i, j]) else "-"
                s = "%.3g" % scalar[i, j] if np.isfinite(scalar[i, j]) else "-"
                txt = "L2 %s\nscalar %s" % (r, s) + ("\ntrain" if train[i, j] else "")
                bright = not np.isfinite(rel_l2[i, j]) or rel_l2[i, j] > 0.6 * vmax
            ax.text(j, i, txt, ha="center", va="center", fontsize=6,
                    color="black" if bright else "white",
                    fontweight="bold" if train[i, j] else "normal")
            if train[i, j]:
                ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, ec="#D55E00", lw=1.6))
    ax.set_xticks(range(nc))
    ax.set_xticklabels(scen, rotation=20, ha="right")
    ax.set_yticks(range(ns))
    ax.set_yticklabels(names)
    ax.tick_params(top=False, right=False, length=0)
    ax.set_xlabel("scenario (outlined: trained on)")
    ax.set_ylabel("parameter set")
    cb = fig.colorbar(im, ax=ax, fraction=0.05, pad=0.02)
    cb.set_label(r"rel. $L_2$ error (mean of $\phi$, $u$, $P$, $T$)", fontsize=7)
    fig.tight_layout()
    writer.save(fig, STEM)
    return []
