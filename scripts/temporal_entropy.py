#!/usr/bin/env python3
"""Would frame-to-frame prediction pay on a cache? For frames of
NAME.####.vdb (pyopenvdb), the zero-order entropy in bits per voxel of three
residuals of the active values, quantised to 1e-6: the 3-D Lorenzo
predictor within the frame (what a spatial coder exploits), the same voxel
in the previous frame (temporal), and the Lorenzo predictor of the
frame-to-frame difference (both). Lower is better.
  scripts/temporal_entropy.py FOLDER STEM [FRAME ...]   (default frames: 3 7 12)"""
import collections
import math
import sys

sys.path.insert(0, "/usr/lib/python3/dist-packages")
import numpy as np  # noqa: E402
import pyopenvdb as vdb  # noqa: E402


def entropy(x):
    counts = collections.Counter(x.tolist())
    n = len(x)
    return -sum(c / n * math.log2(c / n) for c in counts.values())


def lorenzo(a):
    return (a[:-1, 1:, 1:] + a[1:, :-1, 1:] + a[1:, 1:, :-1] - a[:-1, :-1, 1:] - a[:-1, 1:, :-1] - a[1:, :-1, :-1] + a[:-1, :-1, :-1])


folder, stem = sys.argv[1], sys.argv[2]
frames = [int(f) for f in sys.argv[3:]] or [3, 7, 12]
grids = {f: vdb.readAll("%s/%s.%04d.vdb" % (folder, stem, f))[0][0] for n in frames for f in (n - 1, n)}
boxes = [g.evalActiveVoxelBoundingBox() for g in grids.values()]
lo = [min(b[0][a] for b in boxes) - 1 for a in range(3)]
hi = [max(b[1][a] for b in boxes) + 1 for a in range(3)]
dense = {}
for f, g in grids.items():
    a = np.zeros(tuple(hi[i] - lo[i] + 1 for i in range(3)), dtype=np.float32)
    g.copyToArray(a, ijk=lo)
    dense[f] = a.astype(np.float64)
for n in frames:
    a, p, g = dense[n], dense[n - 1], grids[n]
    active = np.zeros(a.shape, dtype=bool)
    for item in g.citerOnValues():
        (x0, y0, z0), (x1, y1, z1) = item.min, item.max
        active[x0 - lo[0]:x1 - lo[0] + 1, y0 - lo[1]:y1 - lo[1] + 1, z0 - lo[2]:z1 - lo[2] + 1] = True
    m = active[1:, 1:, 1:]
    q = lambda r: np.round(r[m] / 1e-6).astype(np.int64)  # noqa: E731
    spatial = entropy(q(a[1:, 1:, 1:] - lorenzo(a)))
    temporal = entropy(q(a[1:, 1:, 1:] - p[1:, 1:, 1:]))
    d = a - p
    both = entropy(q(d[1:, 1:, 1:] - lorenzo(d)))
    print("%s frame %d: %d active voxels; bits/voxel spatial %.2f, temporal %.2f, temporal+spatial %.2f"
          % (stem, n, int(m.sum()), spatial, temporal, both))
