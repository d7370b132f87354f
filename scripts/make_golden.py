#!/usr/bin/env python3
"""Writes the golden files of tests/golden/: small OpenVDB grids (float level
set and fog with tiles and an inactive value, vec3s and bool grids, made
with pyopenvdb, OpenVDB's own Python module) and a small int16 scan
and their .ssvdag made by the current writer. Run once per format version;
the .ssvdag files are kept so that every later version must still read them
(tests/unit/test_golden.cpp decodes each and compares it with its source:
the .vdb tree by tree, the scan byte for byte).

    scripts/make_golden.py build/vdbdag tests/golden
"""
import os
import subprocess
import sys

import numpy as np
import pyopenvdb as vdb


def grids():
    rng = np.random.default_rng(2026)
    ls = vdb.createLevelSetSphere(radius=9.0, center=(0.5, -1.0, 2.0), voxelSize=1.0, halfWidth=3.0)
    ls.name = "sphere"
    ls.transform = vdb.createLinearTransform(voxelSize=0.25)
    fog = vdb.FloatGrid(0.0)
    fog.name = "density"
    fog.gridClass = vdb.GridClass.FOG_VOLUME
    fog.fill((0, 0, 0), (15, 15, 15), 0.5)          # active tiles of 8^3
    acc = fog.getAccessor()
    for _ in range(400):
        acc.setValueOn(tuple(int(v) for v in rng.integers(-20, 20, 3)), float(rng.random()))
    acc.setValueOff((30, 30, 30), 0.25)              # an inactive value that is not the background
    vel = vdb.Vec3SGrid()
    vel.name = "velocity"
    acc = vel.getAccessor()
    for _ in range(300):
        acc.setValueOn(tuple(int(v) for v in rng.integers(-10, 10, 3)), tuple(float(v) for v in rng.normal(size=3)))
    flags = vdb.BoolGrid(False)
    flags.name = "flags"
    acc = flags.getAccessor()
    for _ in range(300):
        acc.setValueOn(tuple(int(v) for v in rng.integers(-10, 10, 3)), bool(rng.integers(0, 2)))
    return {"levelset": [ls], "fog": [fog], "mixed": [vel, flags]}


def main():
    tool, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    sources = []
    for name, gs in grids().items():
        src = os.path.join(out, name + ".vdb")
        vdb.write(src, grids=gs)
        sources.append((name, src))
    # Debian's pyopenvdb has float, bool and vec3s grids only: the integer
    # channel (predicted windows) comes from a small int16 scan, which
    # decodes back to the same raw bytes.
    z, y, x = np.meshgrid(np.arange(10), np.arange(20), np.arange(24), indexing="ij")
    labels = ((x // 6) * 40 + (y // 5) * 7 - z * 3 - 50).astype("<i2")
    raw = os.path.join(out, "labels_24x20x10_int16le.raw")
    labels.tofile(raw)
    sources.append(("labels", raw))
    # labels_coding17 (added 2026-12-06, label model generation 2): a Voronoi
    # atlas of 24 labels, which the writer codes as labels.
    rng = np.random.default_rng(17)
    z, y, x = np.meshgrid(np.arange(16), np.arange(32), np.arange(32), indexing="ij")
    seeds, ids = rng.integers(0, 32, (24, 3)), rng.permutation(np.arange(1, 250))[:24]
    d = np.stack([(x - s[0]) ** 2 + (y - s[1]) ** 2 + (z * 2 - s[2]) ** 2 for s in seeds])
    voronoi = os.path.join(out, "labels_voronoi_32x32x16_uint8.raw")
    ids[np.argmin(d, axis=0)].astype(np.uint8).tofile(voronoi)
    sources.append(("labels_coding17", voronoi))
    # labels_coding18 (added 2026-12-06, label model generation 3): 5 labels,
    # whose 5 uniform 8^3 blocks the writer stores as tiles, their
    # attribute offsets at rest.
    rng = np.random.default_rng(18)
    seeds, ids = rng.integers(0, 32, (5, 3)), rng.permutation(np.arange(1, 250))[:5]
    d = np.stack([(x - s[0]) ** 2 + (y - s[1]) ** 2 + (z * 2 - s[2]) ** 2 for s in seeds])
    tiled = os.path.join(out, "labels_tiled_32x32x16_uint8.raw")
    ids[np.argmin(d, axis=0)].astype(np.uint8).tofile(tiled)
    sources.append(("labels_coding18", tiled))
    for name, src in sources:
        subprocess.run([tool, "encode", src, "-o", os.path.join(out, name + ".ssvdag"), "-f", "-q"], check=True, stdout=subprocess.DEVNULL)
    print("wrote", sorted(os.listdir(out)))


if __name__ == "__main__":
    main()
