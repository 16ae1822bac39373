"""Run by pvpython: open an XDMF sidecar with each of ParaView's three XDMF
readers and check what they show against the HDF5 file (h5py).

    pvpython --force-offscreen-rendering paraview_check.py readers OUT.xdmf OUT.h5
    pvpython --force-offscreen-rendering paraview_check.py plot_over_line OUT.xdmf OUT.h5

readers: every [nt][n] dataset of OUT.h5 (the fields; not /z, the cells'
positions) is a cell array of every reader, at the first and the last time
step, equal to the HDF5 row exactly (the same float64/int32 values; NaN
where the HDF5 file has NaN); the times are /t; the mesh is the column of
cells lo + j dz along Z (one cell wide in X and Y); with an ekm output's
/z of a row per frame (issue 32: a pressure-held wall moves the cells),
the cell centres ParaView computes at those two steps are that frame's /z
(1e-12 of the column's height).

plot_over_line: Plot Over Line along Z through the column (1001 uniform
samples) returns at each sample the HDF5 value of the cell holding it (at
a cell face, the value of either neighbour), for every field; a sample
whose position (ParaView's points are float32) rounds to outside the
column holds no cell (the last one, at the top of the shear cell's 38.4 mm
gap).

Exit 0 when all hold, 1 with one line per failure.
"""
import sys

import h5py
import numpy as np
from paraview import servermanager
from paraview import simple
from vtk.numpy_interface import dataset_adapter as dsa

READERS = ("XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT")


def open_reader(name, xdmf):
    if name == "XDMFReader":
        return simple.XDMFReader(FileNames=[xdmf])
    return getattr(simple, name)(FileName=[xdmf])


def timesteps(reader):
    reader.UpdatePipelineInformation()
    ts = reader.TimestepValues
    return [ts] if isinstance(ts, float) else list(ts)


def profile_fields(h5):
    """Names of the [nt][n] datasets (the profiles; /z, each frame's cell
    centres, is the geometry), nt and n."""
    nt, n = len(h5["t"]), None
    names = []
    for key, obj in h5.items():
        if key != "z" and isinstance(obj, h5py.Dataset) and obj.ndim == 2 and obj.shape[0] == nt:
            names.append(key)
            n = obj.shape[1]
    return sorted(names), nt, n


def column(h5, n, frame):
    """lo and dz of the cells of frame `frame` along z (docs/output-format.md,
    docs/compare.md)."""
    if "lo" in h5.attrs:  # ekmcompare cg
        return float(h5.attrs["lo"]), float(h5.attrs["dz"])
    length = float(h5.attrs["domain.length"]) if "domain.length" in h5.attrs else None
    if "gap" in h5:
        length = float(h5["gap"][frame])
    if length is None:  # the cell centres are (j + 1/2) dz
        z = h5["z"][frame] if h5["z"].ndim == 2 else h5["z"][:]
        return 0.0, float(z[1] - z[0]) if n > 1 else 2.0 * float(z[0])
    return 0.0, length / n


def cell_centres(reader, t):
    """The cell centres ParaView computes for the reader's mesh at time t
    (the Cell Centers filter): an array [n][3]."""
    centres = simple.CellCenters(Input=reader)
    centres.UpdatePipeline(t)
    points = np.asarray(dsa.WrapDataObject(servermanager.Fetch(centres)).Points)
    simple.Delete(centres)
    return points


def check_readers(xdmf, path):
    failures = []
    h5 = h5py.File(path, "r")
    names, nt, n = profile_fields(h5)
    t = h5["t"][:]
    for rname in READERS:
        reader = open_reader(rname, xdmf)
        ts = timesteps(reader)
        if len(ts) != nt or not np.allclose(ts, t, rtol=0, atol=0):
            failures.append("%s: times %s, expected /t %s" % (rname, ts, list(t)))
            continue
        centred = 0
        for frame in sorted({0, nt - 1}):
            reader.UpdatePipeline(ts[frame])
            data = dsa.WrapDataObject(servermanager.Fetch(reader))
            got = sorted(data.CellData.keys())
            if got != names:
                failures.append("%s, t = %g: cell arrays %s, expected %s" % (rname, t[frame], got, names))
            for name in names:
                if name not in data.CellData.keys():
                    continue
                values = np.asarray(data.CellData[name])
                want = h5[name][frame]
                nan_ok = want.dtype.kind == "f"  # cg: NaN where a bin has no data
                if values.shape != want.shape or not np.array_equal(values, want, equal_nan=nan_ok):
                    same = (values == want) | (np.isnan(values) & np.isnan(want)) if nan_ok else values == want
                    bad = np.nonzero(~same)[0] if values.shape == want.shape else "shape"
                    failures.append("%s, t = %g: %s differs from the HDF5 row (cells %s)"
                                    % (rname, t[frame], name, bad))
            lo, dz = column(h5, n, frame)
            bounds = data.GetBounds()
            want_bounds = (0.0, dz, 0.0, dz, lo, lo + n * dz)
            if not np.allclose(bounds, want_bounds, rtol=1e-12, atol=1e-15):
                failures.append("%s, t = %g: bounds %s, expected the column %s along Z"
                                % (rname, t[frame], bounds, want_bounds))
            if "z" in h5 and h5["z"].ndim == 2:  # an ekm output: each frame's centres
                want_z = h5["z"][frame]
                got = cell_centres(reader, ts[frame])
                if got.shape != (n, 3):
                    failures.append("%s, t = %g: %s cell centres, expected %d (/z[%d])"
                                    % (rname, t[frame], got.shape, n, frame))
                elif np.max(np.abs(got[:, 2] - want_z)) > 1e-12 * n * dz:
                    failures.append("%s, t = %g: cell centres along Z %g .. %g m, expected /z[%d] %g .. %g m "
                                    "(up to %g m apart)"
                                    % (rname, t[frame], got[0, 2], got[-1, 2], frame, want_z[0], want_z[-1],
                                       np.max(np.abs(got[:, 2] - want_z))))
                else:
                    centred += 1
        simple.Delete(reader)
        print("%s: %d arrays x %d cells, times %s: checked at t = %g and %g%s"
              % (rname, len(names), n, list(t), t[0], t[-1],
                 "; cell centres = /z of %d frames" % centred if centred else ""))
    return failures


def check_plot_over_line(xdmf, path):
    failures = []
    h5 = h5py.File(path, "r")
    names, nt, n = profile_fields(h5)
    frame = nt - 1
    lo, dz = column(h5, n, frame)
    for rname in READERS:
        reader = open_reader(rname, xdmf)
        ts = timesteps(reader)
        line = simple.PlotOverLine(Input=reader)
        line.Point1 = [0.5 * dz, 0.5 * dz, lo]
        line.Point2 = [0.5 * dz, 0.5 * dz, lo + n * dz]
        line.SamplingPattern = "Sample Uniformly"
        line.Resolution = 1000
        line.UpdatePipeline(ts[frame])
        data = dsa.WrapDataObject(servermanager.Fetch(line))
        z = np.asarray(data.Points, dtype=float)[:, 2]  # float32 points, compared in float64
        for name in names:
            if name not in data.PointData.keys():
                failures.append("%s: Plot Over Line has no %s" % (rname, name))
                continue
            values = np.asarray(data.PointData[name])
            want = h5[name][frame]
            pos = (z - lo) / dz
            below = np.clip(np.floor(pos).astype(int), 0, n - 1)
            face = np.abs(pos - np.round(pos)) < 1e-9
            above = np.where(face, np.clip(np.round(pos).astype(int), 0, n - 1), below)
            below = np.where(face, np.clip(np.round(pos).astype(int) - 1, 0, n - 1), below)
            def same(a, b):
                return (a == b) | (np.isnan(a) & np.isnan(b)) if want.dtype.kind == "f" else a == b

            outside = (z < lo) | (z > lo + n * dz)
            ok = same(values, want[below]) | same(values, want[above]) | outside
            if not ok.all():
                failures.append("%s, t = %g: Plot Over Line of %s wrong at %d of %d samples (first z = %g)"
                                % (rname, ts[frame], name, int((~ok).sum()), len(z), z[~ok][0]))
        print("%s: Plot Over Line, %d samples x %d fields at t = %g" % (rname, len(z), len(names), ts[frame]))
        simple.Delete(line)
        simple.Delete(reader)
    return failures


def main():
    what, xdmf, path = sys.argv[1:4]
    failures = check_readers(xdmf, path) if what == "readers" else check_plot_over_line(xdmf, path)
    for f in failures:
        print("FAIL: " + f)
    sys.exit(1 if failures else 0)


main()
