"""The ParaView reader plugin as a user meets it, against independent readers.

ParaView (pvpython, dump_image.py) loads the plugin from the build tree,
opens .ssvdag files through its reader factory and hands back images; this
script (Debian's python3) compares them with what OpenVDB (pyopenvdb's
copyToArray, i.e. copyToDense, and its transform) and nibabel read from the
files the .ssvdag files were made from:
  - a level set at level of detail 0 (every voxel of the active box, the
    inactive inside keeping its sign) and 2 (every 4th voxel);
  - a fog with active tiles under a 1-million-point budget: the level is the
    finest whose image fits, and the samples are OpenVDB's at that stride;
  - a file of several grids (vectors, integers, a level set): one array per
    grid of the first grid's transform;
  - a box given in index coordinates, partly outside the grid (background);
  - a NIfTI scan with an oblique affine: every sample equal to nibabel's, and
    each point's position equal to the affine's (in LPS, as vdbdag stores
    patient space) at levels 0 and 1;
  - the .vdb files themselves (OpenVDB's reader inside the plugin): the same
    images as their .ssvdag files;
  - a comparison (CompareWith) of the level set with a copy changed by
    pyopenvdb (values changed, voxels switched off and on), as .ssvdag and
    as .vdb: a, b, abs_error and status at every point equal those computed
    here from OpenVDB's accessor on both files;
  - a numbered series of .ssvdag files (OpenVDB's level-set advection) as
    one source with a time step per file, each step the image of its frame;
  - ../shared's bunny level set, when present: a box through its surface at
    level 0 from its .ssvdag and from the .vdb, and a contour at 0 of the
    default image, which has points;
  - Output Type "Active Voxels" (cells) of a fog with tiles and of the
    several grids, in a box: expanded to voxels, exactly OpenVDB's active
    voxels of the box with their values, from the .ssvdag and the .vdb;
  - truncated .ssvdag and .vdb files, and more active cells than Maximum
    Cells: ParaView reports each, naming the file, and does not crash.
usage: check_plugin.py BUILD_DIR PLUGIN.so PVPYTHON PV_SITE_PACKAGES
"""
import json
import os
import subprocess
import sys
import tempfile

import nibabel as nib
import numpy as np
import pyopenvdb as vdb

BUILD, PLUGIN, PVPYTHON, PV_SITE = sys.argv[1:5]
HERE = os.path.dirname(os.path.abspath(__file__))
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def run(*args):
    subprocess.run(list(args), check=True, stdout=subprocess.DEVNULL)


def dump(work, cases):
    spec = os.path.join(work, "cases.json")
    with open(spec, "w") as f:
        json.dump(cases, f)
    done = subprocess.run([PVPYTHON, os.path.join(HERE, "dump_image.py"), PV_SITE, PLUGIN, spec],
                          capture_output=True, text=True, timeout=600)
    print(done.stdout, end="")
    return done


def pv_values(image, index):
    """ParaView's array `index` as [i, j, k(, c)], from VTK's x-fastest order."""
    nx, ny, nz = image["dims"]
    a = image["array_%d" % index]
    comps = a.shape[1] if a.ndim == 2 else 1
    a = a.reshape(nz, ny, nx, comps).transpose(2, 1, 0, 3)
    return a[..., 0] if comps == 1 else a


def vdb_dense(grid, lo, hi):
    """OpenVDB's values of the inclusive index box [lo, hi] (copyToDense)."""
    shape = tuple(int(h - l + 1) for l, h in zip(lo, hi))
    if grid.valueTypeName.startswith("vec3"):
        shape = shape + (3,)
    dtype = {"float": np.float32, "double": np.float64, "int32": np.int32, "int64": np.int64, "bool": np.bool_,
             "vec3s": np.float32, "vec3d": np.float64, "vec3i": np.int32}[grid.valueTypeName]
    out = np.zeros(shape, dtype=dtype)
    grid.copyToArray(out, ijk=tuple(int(v) for v in lo))
    return out


def probe(vdb_file, grid, lo, hi):
    """OpenVDB's accessor (vdbdag_vdb_probe) on every voxel of [lo, hi], i fastest
    (a VTK image's point order): (coordinates (N, 3) as i, j, k; active flags;
    value bytes as an (N, bytes) uint8 array)."""
    axes = np.ogrid[lo[2]:hi[2] + 1, lo[1]:hi[1] + 1, lo[0]:hi[0] + 1]
    ijk = np.stack(np.broadcast_arrays(*axes), axis=-1).reshape(-1, 3)[:, ::-1]
    text = "\n".join("%d %d %d" % tuple(c) for c in ijk) + "\n"
    lines = subprocess.run([os.path.join(BUILD, "vdbdag_vdb_probe"), "values", vdb_file, grid], input=text,
                           check=True, capture_output=True, text=True).stdout.split()
    active = np.array([v == "1" for v in lines[0::2]])
    values = np.frombuffer(bytes.fromhex("".join(lines[1::2])), dtype=np.uint8).reshape(len(ijk), -1)
    return ijk, active, values


def check_geometry(name, image, grid, lo, stride):
    origin = np.array(grid.transform.indexToWorld(tuple(float(v) for v in lo)))
    check(np.allclose(image["origin"], origin, rtol=0, atol=1e-9), "%s: origin %s is OpenVDB's %s" % (name, image["origin"], origin))
    spacing = np.array(grid.transform.voxelSize()) * stride
    check(np.allclose(image["spacing"], spacing, rtol=1e-12), "%s: spacing %s is OpenVDB's voxel size x %d" % (name, image["spacing"], stride))


def check_values(name, got, want):
    same = got.shape == want.shape and np.array_equal(got.view(np.uint8) if got.dtype == np.bool_ else got,
                                                       want.astype(got.dtype))
    if not same and got.shape == want.shape:
        bad = np.argwhere(got != want.astype(got.dtype))
        print("     first differing samples:", bad[:3].tolist())
    check(same, "%s: %s samples equal OpenVDB's bit for bit" % (name, "x".join(map(str, got.shape))))


with tempfile.TemporaryDirectory() as work:
    run(os.path.join(BUILD, "vdbdag_make_samples"), work)
    for stem in ("sphere_ls", "fog_tiles", "multi_grid"):
        run(os.path.join(BUILD, "vdbdag"), "encode", os.path.join(work, stem + ".vdb"), "-o", os.path.join(work, stem + ".ssvdag"), "-q")

    # A NIfTI scan: int16, an oblique affine (rotated, anisotropic), smooth with noise.
    rng = np.random.default_rng(7)
    i, j, k = np.meshgrid(np.arange(37), np.arange(30), np.arange(11), indexing="ij")
    scan = (600 * np.sin(i / 5.0) * np.cos(j / 7.0) + 40 * k + rng.integers(-30, 30, i.shape)).astype(np.int16)
    c, s = np.cos(0.3), np.sin(0.3)
    affine = np.array([[0.7 * c, -0.8 * s, 0, -12.5], [0.7 * s, 0.8 * c, 0, 30.25], [0, 0, 2.5, -40], [0, 0, 0, 1]])
    img = nib.Nifti1Image(scan, affine)
    img.set_qform(affine, code=1)
    img.set_sform(affine, code=1)
    nib.save(img, os.path.join(work, "scan.nii.gz"))
    run(os.path.join(BUILD, "vdbdag"), "encode", os.path.join(work, "scan.nii.gz"), "-o", os.path.join(work, "scan.ssvdag"), "-q")
    with open(os.path.join(work, "scan.ssvdag"), "rb") as f:
        head = f.read(4096)
    with open(os.path.join(work, "truncated.ssvdag"), "wb") as f:
        f.write(head)

    w = lambda name: os.path.join(work, name)  # noqa: E731
    # ../shared's bunny level set, when present: a box through its surface at
    # level 0, from its .ssvdag and from the .vdb itself, and its contour.
    bunny = os.path.join(HERE, "..", "..", "..", "shared", "data", "levelsets", "bunny_d512_ls.vdb")
    if os.path.exists(bunny):
        run(os.path.join(BUILD, "vdbdag"), "encode", bunny, "-o", w("bunny.ssvdag"), "-q")
    else:
        print("skip: ../shared/data absent, the bunny checks do not run")
    # A copy of the level set changed by OpenVDB itself: 50 values changed,
    # 30 voxels switched off, 20 inactive voxels switched on.
    changed = vdb.read(w("sphere_ls.vdb"), "sphere")
    acc = changed.getAccessor()
    on = [tuple(int(c) for c in ijk) for ijk in rng.integers(-30, 31, (4000, 3)) if acc.isValueOn(tuple(int(c) for c in ijk))]
    off = [tuple(int(c) for c in ijk) for ijk in rng.integers(-42, 43, (4000, 3)) if not acc.isValueOn(tuple(int(c) for c in ijk))]
    for ijk in on[:50]:
        acc.setValueOn(ijk, acc.getValue(ijk) + 0.5)
    for ijk in on[50:80]:
        acc.setActiveState(ijk, False)
    for ijk in off[:20]:
        acc.setValueOn(ijk, 1.25)
    vdb.write(w("sphere_mod.vdb"), grids=[changed])
    run(os.path.join(BUILD, "vdbdag"), "encode", w("sphere_mod.vdb"), "-o", w("sphere_mod.ssvdag"), "-q")
    # A frame sequence made with OpenVDB's level-set advection, one .ssvdag per frame.
    run(os.path.join(BUILD, "vdbdag_make_sequence"), w("seq"), "--frames", "3", "--dim", "64", "--no-fog")
    frames = [w("seq/levelset.%04d" % n) for n in (1, 2, 3)]
    for f in frames:
        run(os.path.join(BUILD, "vdbdag"), "encode", f + ".vdb", "-o", f + ".ssvdag", "-q")
    # The same frames in one sequence file: its frames are the time steps.
    run(os.path.join(BUILD, "vdbdag"), "encode", w("seq/levelset.####.vdb"), "-o", w("seq/all.ssvdag"), "-q")
    cases = [
        {"file": w("sphere_ls.ssvdag"), "out": w("sphere0.npz")},
        {"file": w("sphere_ls.ssvdag"), "out": w("sphere2.npz"), "properties": {"LevelOfDetail": 2}},
        {"file": w("fog_tiles.ssvdag"), "out": w("fog.npz"), "properties": {"MaximumCells": 1.0}},
        {"file": w("multi_grid.ssvdag"), "out": w("multi.npz")},
        {"file": w("sphere_ls.ssvdag"), "out": w("box.npz"), "properties": {"UseBox": 1, "Box": [-50, 10, -5, 5, 30, 60]}},
        {"file": w("scan.ssvdag"), "out": w("scan0.npz")},
        {"file": w("scan.ssvdag"), "out": w("scan1.npz"), "properties": {"LevelOfDetail": 1}},
        {"file": w("sphere_ls.vdb"), "out": w("sphere0_vdb.npz")},
        {"file": w("fog_tiles.vdb"), "out": w("fog_vdb.npz"), "properties": {"MaximumCells": 1.0}},
        {"file": w("multi_grid.vdb"), "out": w("multi_vdb.npz")},
        {"file": w("sphere_ls.ssvdag"), "out": w("diff.npz"), "properties": {"CompareWith": w("sphere_mod.ssvdag")}},
        {"file": w("sphere_ls.ssvdag"), "out": w("diff_vdb.npz"), "properties": {"CompareWith": w("sphere_mod.vdb")}},
    ] + [{"file": [f + ".ssvdag" for f in frames], "time": float(t), "out": w("frame%d.npz" % t)} for t in (2, 0, 1)]
    cases += [{"file": w("seq/all.ssvdag"), "time": float(n), "out": w("seqframe%d.npz" % n)} for n in (3, 1, 2)]
    cases += [{"file": w("seq/all.ssvdag"), "time": 2.0, "out": w("seqcells.npz"), "properties": {"OutputType": 1}}]
    cases += [{"file": w(name), "out": w(name + ".cells.npz"), "properties": {"OutputType": 1, "UseBox": 1, "Box": box}}
              for name, box in (("fog_tiles.ssvdag", [-60, 20, -30, 40, -50, 10]), ("fog_tiles.vdb", [-60, 20, -30, 40, -50, 10]),
                                ("multi_grid.ssvdag", [-50, 50, -50, 50, -50, 50]), ("multi_grid.vdb", [-50, 50, -50, 50, -50, 50]))]
    bunny_box = [-40, 55, -10, 85, -60, 35]  # x0 x1 y0 y1 z0 z1, through the ear's base and the back
    if os.path.exists(bunny):
        for name in ("bunny.ssvdag", "bunny.vdb"):
            cases.append({"file": w("bunny.ssvdag") if name.endswith("ssvdag") else bunny, "out": w(name + ".npz"),
                          "properties": {"UseBox": 1, "Box": bunny_box, "LevelOfDetail": 0}})
            cases.append({"file": w("bunny.ssvdag") if name.endswith("ssvdag") else bunny, "out": w(name + ".contour.npz"), "contour": 0.0})
    done = dump(work, cases)
    check(done.returncode == 0, "pvpython loaded the plugin and read %d images (exit %d)" % (len(cases), done.returncode))
    if done.returncode != 0:
        print(done.stderr[-3000:])
        sys.exit(1)
    load = lambda name: np.load(w(name))  # noqa: E731

    # The level set: levels 0 and 2 against copyToDense of its active box.
    sphere = vdb.read(w("sphere_ls.vdb"), "sphere")
    lo, hi = sphere.evalActiveVoxelBoundingBox()
    dense = vdb_dense(sphere, lo, hi)
    for name, stride in (("sphere0.npz", 1), ("sphere2.npz", 4)):
        image = load(name)
        check(int(image["level"]) == int(np.log2(stride)), "%s: level %d" % (name, int(image["level"])))
        check(list(image["arrays"]) == ["sphere"], "%s: one array named as the grid" % name)
        check_geometry(name, image, sphere, lo, stride)
        check_values(name, pv_values(image, 0), dense[::stride, ::stride, ::stride])
    check(float(pv_values(load("sphere0.npz"), 0)[42, 42, 42]) < 0, "sphere0.npz: the inactive inside keeps the level set's sign")

    # The fog under a budget of 10^6 points: the finest level that fits.
    fog = vdb.read(w("fog_tiles.vdb"), "density")
    lo, hi = fog.evalActiveVoxelBoundingBox()
    counts = [np.prod([(h - l) // (1 << L) + 1 for l, h in zip(lo, hi)]) for L in range(8)]
    want_level = next(L for L in range(8) if counts[L] <= 1e6)
    image = load("fog.npz")
    check(int(image["level"]) == want_level and want_level > 0,
          "fog.npz: level %d is the finest within 10^6 points (%s points per level)" % (int(image["level"]), counts[:want_level + 1]))
    stride = 1 << want_level
    check_geometry("fog.npz", image, fog, lo, stride)
    check_values("fog.npz", pv_values(image, 0), vdb_dense(fog, lo, hi)[::stride, ::stride, ::stride])

    # Several grids (vectors, int32, bool: pyopenvdb reads only some types, so
    # OpenVDB's accessor through vdbdag_vdb_probe): one array each, of the
    # grids sharing the first grid's transform.
    meta = json.loads(subprocess.run([os.path.join(BUILD, "vdbdag_vdb_probe"), "meta", w("multi_grid.vdb")],
                                     check=True, capture_output=True, text=True).stdout)["grids"]
    same = [g for g in meta if g["index_to_world"] == meta[0]["index_to_world"]]
    field = lambda g, key: [int(v) for v in next(m["value"] for m in g["metadata"] if m["name"] == key).strip("[]").split(",")]  # noqa: E731
    lo = [min(field(g, "file_bbox_min")[a] for g in same) for a in range(3)]
    hi = [max(field(g, "file_bbox_max")[a] for g in same) for a in range(3)]
    image = load("multi.npz")
    names = [g["name"] or "grid" for g in same]  # an unnamed grid is "grid"
    check(list(image["arrays"]) == names, "multi.npz: arrays %s are the grids of the first grid's transform %s" % (list(image["arrays"]), names))
    check(np.allclose(image["origin"], np.array(lo + [1.0]) @ np.array(meta[0]["index_to_world"]).reshape(4, 4)[:, :3]),
          "multi.npz: origin %s is OpenVDB's transform of %s" % (image["origin"], lo))
    for n, g in enumerate(same):
        _, _, want = probe(w("multi_grid.vdb"), g["name"], lo, hi)
        got = np.ascontiguousarray(image["array_%d" % n]).view(np.uint8).reshape(len(want), -1)  # i fastest, as the probe's
        check(np.array_equal(got, want), "multi.npz '%s' (%s): %d samples equal OpenVDB's accessor bit for bit" % (names[n], g["type"], len(want)))

    # A box partly outside the grid.
    image = load("box.npz")
    check(list(image["dims"]) == [61, 11, 31], "box.npz: dims %s for the box x -50..10, y -5..5, z 30..60" % list(image["dims"]))
    check_geometry("box.npz", image, sphere, (-50, -5, 30), 1)
    check_values("box.npz", pv_values(image, 0), vdb_dense(sphere, (-50, -5, 30), (10, 5, 60)))

    # The scan: nibabel's samples, and each point where the affine puts it (LPS).
    lps = np.diag([-1.0, -1.0, 1.0, 1.0]) @ nib.load(w("scan.nii.gz")).affine
    stored = np.asarray(nib.load(w("scan.nii.gz")).dataobj)
    for name, stride in (("scan0.npz", 1), ("scan1.npz", 2)):
        image = load(name)
        want = stored[::stride, ::stride, ::stride]
        check(list(image["dims"]) == list(want.shape), "%s: dims %s are nibabel's %s every %d" % (name, list(image["dims"]), want.shape, stride))
        check(np.array_equal(pv_values(image, 0), want), "%s: every sample equals nibabel's" % name)
        direction = image["direction"].reshape(3, 3)
        worst = 0.0
        for n in ((0, 0, 0), tuple(d - 1 for d in image["dims"]), (3, 1, 2)):
            paraview_point = image["origin"] + direction @ (image["spacing"] * np.array(n))
            nifti_point = (lps @ np.array([n[0] * stride, n[1] * stride, n[2] * stride, 1.0]))[:3]
            worst = max(worst, float(np.abs(paraview_point - nifti_point).max()))
        check(worst < 1e-4, "%s: points lie where the NIfTI affine puts them (LPS), worst %.2g mm" % (name, worst))

    # The .vdb files read by the plugin through OpenVDB: the same images.
    for ssvdag, vdbfile in (("sphere0.npz", "sphere0_vdb.npz"), ("fog.npz", "fog_vdb.npz"), ("multi.npz", "multi_vdb.npz")):
        x, y = load(ssvdag), load(vdbfile)
        same = all(np.array_equal(x[key], y[key]) for key in ("dims", "origin", "spacing", "direction", "level", "arrays"))
        same = same and all(np.array_equal(x["array_%d" % n], y["array_%d" % n]) for n in range(len(x["arrays"])))
        check(same, "%s: the .vdb read through OpenVDB gives the image of its .ssvdag" % vdbfile)

    # The sequence: three time steps, each the image of its own frame.
    for t in (0, 1, 2):
        image = load("frame%d.npz" % t)
        grid = vdb.read(frames[t] + ".vdb", "surface")
        lo, hi = grid.evalActiveVoxelBoundingBox()
        check(list(image["times"]) == [0.0, 1.0, 2.0], "frame%d.npz: the series has time steps %s" % (t, list(image["times"])))
        check_geometry("frame%d.npz" % t, image, grid, lo, 1)
        check_values("frame%d.npz (levelset.%04d)" % (t, t + 1), pv_values(image, 0), vdb_dense(grid, lo, hi))

    # The sequence file: its frame numbers are the time steps; each is the
    # image of its frame over the box of all frames.
    grids = [vdb.read(f + ".vdb", "surface") for f in frames]
    boxes = [g.evalActiveVoxelBoundingBox() for g in grids]
    lo = [min(b[0][a] for b in boxes) for a in range(3)]
    hi = [max(b[1][a] for b in boxes) for a in range(3)]
    for n in (1, 2, 3):
        image = load("seqframe%d.npz" % n)
        check(list(image["times"]) == [1.0, 2.0, 3.0], "seqframe%d.npz: the sequence file has time steps %s" % (n, list(image["times"])))
        check_geometry("seqframe%d.npz" % n, image, grids[n - 1], lo, 1)
        check_values("seqframe%d.npz (frame %d of all.ssvdag)" % (n, n), pv_values(image, 0), vdb_dense(grids[n - 1], lo, hi))
    cells = load("seqcells.npz")
    edges = np.rint((cells["hi_0"] - cells["lo_0"]) / grids[1].transform.voxelSize()[0]).astype(np.int64)
    voxels = int(np.prod(edges, axis=1).sum())
    check(voxels == grids[1].activeVoxelCount(),
          "seqcells.npz: the active cells at time 2 hold frame 2's %d active voxels (%d)" % (grids[1].activeVoxelCount(), voxels))

    if os.path.exists(bunny):
        grid = vdb.read(bunny, vdb.readAllGridMetadata(bunny)[0].name)
        lo, hi = bunny_box[0::2], bunny_box[1::2]
        want = vdb_dense(grid, lo, hi)
        for name in ("bunny.ssvdag", "bunny.vdb"):
            image = load(name + ".npz")
            check_geometry(name + " box", image, grid, lo, 1)
            check_values(name + " box at level 0 (%d active voxels in it)" % int(np.count_nonzero(np.abs(want) < grid.background)),
                         pv_values(image, 0), want)
            surface = load(name + ".contour.npz")
            check(int(surface["contour_points"]) > 10000, "%s: the contour at 0 of the default image (level %d) has %d points"
                  % (name, int(surface["level"]), int(surface["contour_points"])))

    # Active voxels and tiles as cells, in a box: expanded to voxels, exactly
    # OpenVDB's active voxels in the box (tiles whole) with their values.
    for stem, box in (("fog_tiles", [-60, 20, -30, 40, -50, 10]), ("multi_grid", [-50, 50, -50, 50, -50, 50])):
        meta = json.loads(subprocess.run([os.path.join(BUILD, "vdbdag_vdb_probe"), "meta", w(stem + ".vdb")],
                                         check=True, capture_output=True, text=True).stdout)["grids"]
        lo, hi = box[0::2], box[1::2]
        for kind in ("ssvdag", "vdb"):
            cells = load("%s.%s.cells.npz" % (stem, kind))
            check(list(cells["blocks"]) == [g["name"] or "grid" for g in meta], "%s.%s cells: one block per grid %s" % (stem, kind, list(cells["blocks"])))
            for n, g in enumerate(meta):
                m = np.array(g["index_to_world"]).reshape(4, 4)
                # Each cell's index box: corner 0 and 6 back through the transform (voxel centres at integers).
                inv = np.linalg.inv(m)
                c0 = np.rint((np.c_[cells["lo_%d" % n], np.ones(len(cells["lo_%d" % n]))] @ inv)[:, :3] + 0.5).astype(np.int64)
                c6 = np.rint((np.c_[cells["hi_%d" % n], np.ones(len(cells["hi_%d" % n]))] @ inv)[:, :3] + 0.5).astype(np.int64)
                got = {}
                values = cells["values_%d" % n].reshape(len(c0), -1)
                for a, b, v in zip(c0, c6, values):
                    for z in range(a[2], b[2]):
                        for y in range(a[1], b[1]):
                            for x in range(a[0], b[0]):
                                if lo[0] <= x <= hi[0] and lo[1] <= y <= hi[1] and lo[2] <= z <= hi[2]:
                                    got[(x, y, z)] = v.tobytes()
                ijk, on, val = probe(w(stem + ".vdb"), g["name"], lo, hi)
                want = {tuple(int(v) for v in c): val[i].tobytes() for i, c in enumerate(ijk) if on[i]}
                if g["type"].endswith("bool_5_4_3"):  # bool cells hold one byte, as the probe prints it
                    want = {k: v[:1] for k, v in want.items()}
                if "MaskTree" in g["type"] or "mask" in g["type"]:
                    got = {k: b"" for k in got}
                    want = {k: b"" for k in want}
                check(got == want, "%s.%s cells '%s': %d cells cover the box's %d active voxels with OpenVDB's values (%d wrong or missing)"
                      % (stem, kind, g["name"] or "grid", len(c0), len(want), len(set(want.items()) ^ set(got.items()))))

    # Comparisons: every point of the union of both active boxes.
    lo, hi = [-42, -42, -42], [42, 42, 42]
    _, a_on, a_val = probe(w("sphere_ls.vdb"), "sphere", lo, hi)
    _, b_on, b_val = probe(w("sphere_mod.vdb"), "sphere", lo, hi)
    a_f, b_f = a_val.copy().view(np.float32)[:, 0], b_val.copy().view(np.float32)[:, 0]
    want_status = np.where(a_on & b_on, np.where(np.all(a_val == b_val, axis=1), 0, 1), np.where(a_on, 2, np.where(b_on, 3, 4)))
    want_error = np.where(np.all(a_val == b_val, axis=1), 0.0, np.abs(a_f.astype(np.float64) - b_f.astype(np.float64)))
    counts = np.bincount(want_status, minlength=5)
    for name in ("diff.npz", "diff_vdb.npz"):
        image = load(name)
        check(list(image["arrays"]) == ["a", "b", "abs_error", "status"] and list(image["dims"]) == [85, 85, 85],
              "%s: arrays %s over the 85^3 union box" % (name, list(image["arrays"])))
        got = {str(n): image["array_%d" % i] for i, n in enumerate(image["arrays"])}
        check(np.array_equal(got["a"], a_f) and np.array_equal(got["b"], b_f), "%s: a and b are OpenVDB's values of both files" % name)
        check(np.array_equal(got["status"], want_status),
              "%s: status at every point as OpenVDB's active states and bits say (%s same, %s changed, %s only in A, %s only in B, %s neither)"
              % ((name,) + tuple(counts)))
        check(np.allclose(got["abs_error"], want_error, rtol=0, atol=0), "%s: abs_error = |a - b| at every point" % name)
    check(counts[1] == 50 and counts[2] == 30 and counts[3] == 20, "the changed copy holds 50 changed, 30 switched-off and 20 switched-on voxels")

    # Truncated files: an error naming the file, no crash, no image.
    with open(w("sphere_ls.vdb"), "rb") as f:
        head = f.read(3000)
    with open(w("truncated.vdb"), "wb") as f:
        f.write(head)
    for name in ("truncated.ssvdag", "truncated.vdb", "multi_grid.ssvdag"):
        properties = {"OutputType": 1, "MaximumCells": 0.001} if name == "multi_grid.ssvdag" else {}  # 1000 cells: too few
        done = dump(work, [{"file": w(name), "out": w(name + ".npz"), "properties": properties}])
        line = next((l for l in done.stderr.splitlines() if "vtkVdbdagReader" in l and name in l), "")
        check(done.returncode == 0 and line != "", "%s: ParaView reports an error naming the file: %s" % (name, line.split("): ", 1)[-1][:120]))
        if os.path.exists(w(name + ".npz")):
            saved = np.load(w(name + ".npz"))
            check(np.prod(saved["dims"]) == 0 if "dims" in saved.files else len(saved["blocks"]) == 0, "%s: no image, no cells" % name)

print("%d failure(s)" % len(failures))
sys.exit(1 if failures else 0)
