"""Run by pvpython: ParaView's three XDMF readers open the sidecar of an
`ekmcompare cg --axes x,z` output or of an ekm 2D run (a 2D grid;
continuum/twod/out2d.h) with every [nt][nz][nx]
field (and SE) as a cell array equal to the HDF5 values (NaN where the
file has NaN), at the first and last time step; the mesh spans
x_lo .. x_hi along X, lo .. hi along Z, one cell (dx) thick in Y; the
times are /t.

    pvpython --force-offscreen-rendering paraview2d_check.py OUT.xdmf OUT.h5

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


def main(xdmf, path):
    failures = []
    h5 = h5py.File(path, "r")
    t = h5["t"][:]
    nt = len(t)
    names = sorted(k for k, o in h5.items() if isinstance(o, h5py.Dataset) and o.ndim == 3)
    if not names:
        failures.append("%s: no [nt][nz][nx] dataset" % path)
    nz, nx = h5[names[0]].shape[1:] if names else (0, 0)
    a = h5.attrs
    if "x_lo" in a:  # ekmcompare cg --axes x,z: the grid's attributes
        x_lo, dx, z_lo, dz = (float(a[k]) for k in ("x_lo", "dx", "lo", "dz"))
    else:  # ekm's 2D run: uniform cells from 0, centres /x and /z
        dx, dz = 2.0 * float(h5["x"][0]), 2.0 * float(h5["z"][0])
        x_lo, z_lo = 0.0, 0.0
    want_bounds = (x_lo, x_lo + nx * dx, 0.0, dx, z_lo, z_lo + nz * dz)
    for rname in READERS:
        reader = open_reader(rname, xdmf)
        reader.UpdatePipelineInformation()
        ts = reader.TimestepValues
        ts = [ts] if isinstance(ts, float) else list(ts)
        if nt > 1 and (len(ts) != nt or not np.allclose(ts, t, rtol=0, atol=0)):
            failures.append("%s: times %s, expected /t %s" % (rname, ts, list(t)))
            continue
        for frame in sorted({0, nt - 1}):
            reader.UpdatePipeline(ts[frame] if ts else t[frame])
            data = dsa.WrapDataObject(servermanager.Fetch(reader))
            got = sorted(data.CellData.keys())
            if got != names:
                failures.append("%s, t = %g: cell arrays %s, expected %s" % (rname, t[frame], got, names))
            for name in names:
                if name not in data.CellData.keys():
                    continue
                values = np.asarray(data.CellData[name])
                want = h5[name][frame].reshape(-1)  # x fastest, as VTK's cell order
                if values.shape != want.shape or not np.array_equal(values, want, equal_nan=True):
                    failures.append("%s, t = %g: %s differs from the HDF5 slab" % (rname, t[frame], name))
            bounds = data.GetBounds()
            if not np.allclose(bounds, want_bounds, rtol=1e-12, atol=1e-15):
                failures.append("%s: bounds %s, expected %s" % (rname, bounds, want_bounds))
        simple.Delete(reader)
        print("%s: %d arrays x %d x %d cells, %d time step(s): checked" % (rname, len(names), nx, nz, nt))
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
