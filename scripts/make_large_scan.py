#!/usr/bin/env python3
"""A large 16-bit CT-like scan written slab by slab, in bounded memory (the
phantom tool, samples/make_ct_phantom.cpp, holds the whole volume as floats):
air at -1000 HU, a body of soft tissue (about 40 HU) and a bone shell (about
1000 HU), each with Gaussian noise, as NRRD (detached raw, little-endian).

Usage: scripts/make_large_scan.py OUT_PREFIX X Y Z [--seed N]
Writes OUT_PREFIX.nhdr and OUT_PREFIX.raw (X*Y*Z*2 bytes).
"""
import os
import sys

import numpy as np


def main():
    args = sys.argv[1:]
    seed = 1
    if "--seed" in args:
        i = args.index("--seed")
        seed = int(args[i + 1])
        del args[i:i + 2]
    if len(args) != 4:
        sys.exit(__doc__)
    prefix, nx, ny, nz = args[0], int(args[1]), int(args[2]), int(args[3])
    rng = np.random.default_rng(seed)
    cx, cy, cz = nx / 2, ny / 2, nz / 2
    r_body, r_bone_out, r_bone_in = 0.45 * min(nx, ny, nz * 2), 0.25 * min(nx, ny, nz * 2), 0.21 * min(nx, ny, nz * 2)
    y, x = np.mgrid[0:ny, 0:nx].astype(np.float32)
    raw = prefix + ".raw"
    with open(raw + ".tmp", "wb") as f:
        for z in range(nz):
            # The body is an ellipsoid stretched along z.
            d = np.sqrt((x - cx) ** 2 + (y - cy) ** 2 + ((z - cz) * 2.0) ** 2)
            s = np.full((ny, nx), -1000.0, np.float32)
            s[d < r_body] = 40.0
            s[(d < r_bone_out) & (d >= r_bone_in)] = 1000.0
            s += rng.normal(0.0, 12.0, size=(ny, nx)).astype(np.float32)
            f.write(np.clip(np.rint(s), -32768, 32767).astype("<i2").tobytes())
    os.replace(raw + ".tmp", raw)
    with open(prefix + ".nhdr", "w") as h:
        h.write("NRRD0004\n# scripts/make_large_scan.py\ntype: short\ndimension: 3\n")
        h.write(f"sizes: {nx} {ny} {nz}\nspacings: 0.5 0.5 1\nencoding: raw\nendian: little\n")
        h.write(f"data file: {os.path.basename(raw)}\n")


if __name__ == "__main__":
    main()
