#!/usr/bin/python3
"""cg_numpy.py: the NumPy reference for bench/cg.sh.

Does what `ekmcompare cg` does by default on a z-profile, the way a NumPy
user would: parse the dump (np.loadtxt per snapshot for text and gzip,
np.frombuffer for LAMMPS binary), bin-integrated Gaussian kernel (cut at 3w,
tabulated CDF, reflected at the walls), rho, phi, momentum, V = p/rho, and
the kinetic stress about V interpolated at each particle, averaged over
snapshots. Prints the number of particle-snapshots processed.

usage: /usr/bin/python3 cg_numpy.py DUMP [text|gz|bin]
"""
import gzip
import math
import struct
import sys

import numpy as np


def text_snapshots(f):
    """Yield (natoms, box_z, column names, array) per snapshot."""
    while True:
        line = f.readline()
        if not line:
            return
        if line.startswith("ITEM: NUMBER OF ATOMS"):
            natoms = int(f.readline())
        elif line.startswith("ITEM: BOX BOUNDS"):
            box = [f.readline().split() for _ in range(3)]
            zlo, zhi = float(box[2][0]), float(box[2][1])
            lx = float(box[0][1]) - float(box[0][0])
            ly = float(box[1][1]) - float(box[1][0])
        elif line.startswith("ITEM: ATOMS"):
            cols = line.split()[2:]
            data = np.loadtxt(f, max_rows=natoms, ndmin=2)
            yield natoms, (zlo, zhi, lx * ly), cols, data


def binary_snapshots(path):
    with open(path, "rb") as f:
        buf = f.read()
    pos = 0
    while pos < len(buf):
        (n,) = struct.unpack_from("<q", buf, pos); pos += 8
        if n < 0:
            pos += -n + 8  # magic, endian, revision
            pos += 8       # step
        (natoms,) = struct.unpack_from("<q", buf, pos); pos += 8
        (tri,) = struct.unpack_from("<i", buf, pos); pos += 4 + 24
        b = struct.unpack_from("<6d", buf, pos); pos += 48
        if tri:
            pos += 24
        (size_one,) = struct.unpack_from("<i", buf, pos); pos += 4
        (ulen,) = struct.unpack_from("<i", buf, pos); pos += 4 + ulen
        tflag = buf[pos]; pos += 1
        if tflag:
            pos += 8
        (clen,) = struct.unpack_from("<i", buf, pos); pos += 4
        cols = buf[pos:pos + clen].decode().split(); pos += clen
        (nchunk,) = struct.unpack_from("<i", buf, pos); pos += 4
        parts = []
        for _ in range(nchunk):
            (m,) = struct.unpack_from("<i", buf, pos); pos += 4
            parts.append(np.frombuffer(buf, dtype="<f8", count=m, offset=pos)); pos += 8 * m
        data = np.concatenate(parts).reshape(natoms, size_one)
        yield natoms, (b[4], b[5], (b[1] - b[0]) * (b[3] - b[2])), cols, data


def main():
    path, fmt = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "text"
    if fmt == "bin":
        snaps = binary_snapshots(path)
    else:
        f = gzip.open(path, "rt") if fmt == "gz" else open(path)
        snaps = text_snapshots(f)
    tab_u = np.linspace(-3, 3, 6001)
    lo = 0.5 * math.erfc(3 / math.sqrt(2))
    tab_f = np.array([(0.5 * math.erfc(-u / math.sqrt(2)) - lo) / (1 - 2 * lo) for u in tab_u])
    total, nsnap, acc = 0, 0, None
    for natoms, (zlo, zhi, area), cols, d in snaps:
        c = {n: i for i, n in enumerate(cols)}
        z, r, m = d[:, c["z"]], d[:, c["radius"]], d[:, c["mass"]]
        v = d[:, [c["vx"], c["vy"], c["vz"]]]
        vol = 4.0 / 3.0 * math.pi * r ** 3
        if acc is None:
            w = 2 * r.mean()
            dz = 0.5 * w
            nb = int(math.ceil((zhi - zlo) / dz - 1e-9))
            dz = (zhi - zlo) / nb
            half = int(math.ceil(3 * w / dz)) + 1
            acc = np.zeros((11, nb))
        # weights: for each particle and offset, bin-integrated kernel, with
        # the images reflected at the walls (2 zlo - z, 2 zhi - z)
        base = np.floor((z - zlo) / dz).astype(np.int64)
        rows, wts, owners = [], [], []
        for img in (z, 2 * zlo - z, 2 * zhi - z):
            for o in range(-half, half + 1):
                k = base + o
                e0 = zlo + k * dz - img
                wgt = (np.interp(e0 + dz, tab_u * w, tab_f, 0, 1) - np.interp(e0, tab_u * w, tab_f, 0, 1)) / dz
                ok = (k >= 0) & (k < nb) & (wgt != 0)
                rows.append(k[ok]); wts.append(wgt[ok]); owners.append(np.nonzero(ok)[0])
        k = np.concatenate(rows); wt = np.concatenate(wts); i = np.concatenate(owners)
        rho = np.bincount(k, m[i] * wt, nb) / area
        phi = np.bincount(k, vol[i] * wt, nb) / area
        p = [np.bincount(k, m[i] * v[i, a] * wt, nb) / area for a in range(3)]
        V = [np.where(rho > 0, pa / np.where(rho > 0, rho, 1), 0) for pa in p]
        zc = zlo + (np.arange(nb) + 0.5) * dz
        Vi = np.stack([np.interp(z, zc, Va) for Va in V], axis=1)
        cfl = v - Vi
        K = [np.bincount(k, m[i] * cfl[i, a] * cfl[i, b] * wt, nb) / area
             for a, b in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))]
        acc += np.stack([rho, phi] + p + K)
        total += natoms
        nsnap += 1
    acc /= max(nsnap, 1)
    T = (acc[5] + acc[6] + acc[7]) / (3 * np.where(acc[0] > 0, acc[0], np.nan))
    print(total, float(np.nanmean(T)))


if __name__ == "__main__":
    main()
