"""cost.py: figure 4, the cost chart: wall time of the DEM runs (per
engine, from dem_<engine>.json wall_time_s) and of the EKM runs (ekm.h5
root attribute stats.wall_time_s), each summed over the scenario's sweep
points, as log-scale bars per scenario.
"""
import numpy as np

import common as C


def totals(sc):
    """{source: seconds} summed over the points that have it."""
    out = {}
    for pt in sc.points:
        for e, js in pt.dem_json.items():
            out[e] = out.get(e, 0.0) + float(js["wall_time_s"])
        if pt.ekm is not None:
            out["ekm"] = out.get("ekm", 0.0) + pt.ekm.wall_time
    return out


def _fmt(s):
    if s >= 100:
        return "%.0f" % s
    if s >= 1:
        return "%.1f" % s
    if s >= 0.01:
        return "%.2f" % s
    return "%.0e" % s


def make(scenarios, writer):
    import matplotlib.pyplot as plt
    data = [(sc, totals(sc)) for sc in scenarios]
    data = [(sc, t) for sc, t in data if t]
    if not data:
        return ["no wall times at all: no cost chart"]
    sources = [e for e in C.ENGINES if any(e in t for _, t in data)] + ["ekm"]
    colour = dict(C.ENGINE_COLOUR, ekm="0.25")
    label = dict(C.ENGINE_LABEL, ekm=C.EKM_LABEL)
    hatch = {"liggghts": "", "lammps": "////", "ekm": ""}
    nsrc = len(sources)
    w = 0.8 / nsrc
    fig, ax = plt.subplots(figsize=(C.COLUMN_W, 2.5))
    x = np.arange(len(data))
    vals = [v for _, t in data for v in t.values() if v > 0]
    floor = 10 ** np.floor(np.log10(min(vals)) - 0.3)
    for k, src in enumerate(sources):
        xs, hs = [], []
        for i, (sc, t) in enumerate(data):
            if src in t and t[src] > 0:
                xs.append(x[i] + (k - (nsrc - 1) / 2) * w)
                hs.append(t[src])
        ax.bar(xs, [h - floor for h in hs], bottom=floor, width=w * 0.92, color=colour[src],
               hatch=hatch[src], edgecolor="white" if hatch[src] else colour[src], lw=0.0,
               label=label[src])
        for xx, hh in zip(xs, hs):
            ax.text(xx, hh * 1.12, _fmt(hh), ha="center", va="bottom", fontsize=5.5, rotation=90)
    ax.set_yscale("log")
    ax.set_ylim(floor, max(vals) * 12)
    ax.set_xticks(x)
    ax.set_xticklabels([sc.name.replace("_", " ") for sc, _ in data])
    ax.tick_params(axis="x", which="both", top=False, bottom=False)
    npts = {sc.name: len(sc.points) for sc, _ in data}
    ylabel = "wall time [s]"
    if any(n > 1 for n in npts.values()):
        ylabel += ", sum over sweep points"
    ax.set_ylabel(ylabel)
    ax.legend(loc="upper left", ncol=nsrc, handlelength=1.2, columnspacing=1.0)
    fig.tight_layout()
    writer.save(fig, "cost")
    return []
