"""The Python module against pyopenvdb (Debian's python3-openvdb), an
independent reader of the same grids: values and active states at random
active voxels and random points around them, a dense block, the grid facts,
and encode/decode round trips through the command. Inputs: OpenVDB's own
level-set and fog generators (pyopenvdb.createLevelSetSphere), and the
bunny level set from ../shared/data when it is present."""
import os

import numpy as np
import pytest

import vdbdag

openvdb = pytest.importorskip("pyopenvdb")
SHARED = os.environ.get("VDBDAG_SHARED_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data"))


def sphere_file(work):
    path = os.path.join(work, "sphere.vdb")
    if not os.path.exists(path):
        ls = openvdb.createLevelSetSphere(radius=30.0, center=(1.5, -2.0, 3.0), voxelSize=0.5, halfWidth=3.0)
        ls.name = "sphere"
        fog = openvdb.createLevelSetSphere(radius=20.0, center=(0, 0, 0), voxelSize=1.0, halfWidth=3.0)
        fog.name = "fog"
        fog.transform = openvdb.createLinearTransform(voxelSize=1.0)
        vec = openvdb.Vec3SGrid()
        vec.name = "velocity"
        acc = vec.getAccessor()
        rng = np.random.default_rng(5)
        for _ in range(3000):
            ijk = tuple(int(v) for v in rng.integers(-40, 40, 3))
            acc.setValueOn(ijk, tuple(float(v) for v in rng.normal(size=3)))
        openvdb.write(path, grids=[ls, fog, vec])
    return path


def encoded(work, vdb, **options):
    out = os.path.join(work, os.path.basename(vdb) + ".ssvdag")
    if not os.path.exists(out):
        vdbdag.encode(vdb, out, **options)
    return out


def reference(grid, ijk):
    acc = grid.getConstAccessor()
    values, active = [], []
    for c in ijk:
        v, on = acc.probeValue(tuple(int(x) for x in c))
        values.append(v)
        active.append(on)
    return values, np.array(active, dtype=bool)


def sample_coords(grid, n, seed):
    """Half random active voxels (from pyopenvdb's leaf-value iteration), half uniform around them."""
    rng = np.random.default_rng(seed)
    (x0, y0, z0), (x1, y1, z1) = grid.evalActiveVoxelBoundingBox()
    active = [item.min for item in grid.citerOnValues() if item.count == 1]
    picks = [active[i] for i in rng.integers(0, len(active), n // 2)]
    lo, hi = np.array([x0, y0, z0]) - 8, np.array([x1, y1, z1]) + 8
    around = rng.integers(lo, hi + 1, size=(n - len(picks), 3))
    return np.vstack([np.array(picks, dtype=np.int32).reshape(-1, 3), around.astype(np.int32)])


def check_grid(vdb_path, ssvdag_path, name, n, seed=1):
    ref = openvdb.read(vdb_path, name)
    g = vdbdag.open(ssvdag_path).grid(name)
    ijk = sample_coords(ref, n, seed)
    want_values, want_active = reference(ref, ijk)
    assert np.array_equal(g.is_active(ijk), want_active)
    assert want_active.sum() >= n // 2
    got = g.values(ijk)
    want = np.array(want_values, dtype=got.dtype)
    assert got.shape == want.shape
    assert got.tobytes() == want.tobytes(), "values differ from pyopenvdb's"


def test_level_set_fog_and_vectors_equal_pyopenvdb(work):
    vdb = sphere_file(work)
    path = encoded(work, vdb)
    f = vdbdag.open(path)
    assert [g.name for g in f.grids] == ["sphere", "fog", "velocity"]
    assert [g.value_type for g in f.grids] == ["float", "float", "vec3s"]
    for name in ("sphere", "fog", "velocity"):
        check_grid(vdb, path, name, 20000)


def test_grid_facts_equal_pyopenvdb(work):
    vdb = sphere_file(work)
    g = vdbdag.open(encoded(work, vdb)).grid("sphere")
    ref = openvdb.read(vdb, "sphere")
    assert g.active_voxel_count == ref.activeVoxelCount()
    assert g.index_bbox == tuple(tuple(c) for c in ref.evalActiveVoxelBoundingBox())
    assert g.grid_class == "level set"
    m = g.index_to_world
    assert m.shape == (4, 4)
    assert m[0, 0] == pytest.approx(0.5) and m[3, 3] == 1.0


def test_dense_block_equals_pyopenvdb_copy_to_array(work):
    vdb = sphere_file(work)
    g = vdbdag.open(encoded(work, vdb)).grid("sphere")
    ref = openvdb.read(vdb, "sphere")
    lo, hi = (-10, -70, -5), (25, -40, 20)
    block = g.dense((lo, hi))
    want = np.zeros(tuple(h - l + 1 for l, h in zip(lo, hi)), dtype=np.float32)
    ref.copyToArray(want, ijk=lo)
    assert block.shape == want.shape
    assert block.tobytes() == want.tobytes()


def test_dense_with_a_stride_equals_every_nth_voxel(work):
    vdb = sphere_file(work)
    path = encoded(work, vdb)
    for name, lo, hi in (("sphere", (-70, -70, -60), (70, 66, 70)), ("velocity", (-41, -40, -40), (40, 39, 41))):
        g = vdbdag.open(path).grid(name)
        ref = openvdb.read(vdb, name)
        shape = tuple(h - l + 1 for l, h in zip(lo, hi))
        want = np.zeros(shape + ((3,) if name == "velocity" else ()), dtype=np.float32)
        ref.copyToArray(want, ijk=lo)
        for stride in (1, 3, 8):
            block = g.dense((lo, hi), stride=stride)
            assert block.shape == want[::stride, ::stride, ::stride].shape
            assert block.tobytes() == np.ascontiguousarray(want[::stride, ::stride, ::stride]).tobytes(), (name, stride)


def test_active_voxels_and_tiles_equal_pyopenvdb(work):
    vdb = os.path.join(work, "tiles.vdb")
    grid = openvdb.FloatGrid()
    grid.name = "density"
    grid.fill((0, 0, 0), (31, 15, 7), 2.5)  # tiles where whole 8^3 nodes are filled
    acc = grid.getAccessor()
    rng = np.random.default_rng(3)
    for _ in range(500):
        acc.setValueOn(tuple(int(v) for v in rng.integers(-20, 50, 3)), float(rng.normal()))
    grid.prune()
    openvdb.write(vdb, grids=[grid])
    g = vdbdag.open(encoded(work, vdb)).grid("density")
    # OpenVDB's active values, voxels and tiles, expanded to voxels.
    want = {}
    for item in grid.citerOnValues():
        lo, hi = item["min"], item["max"]
        for z in range(lo[2], hi[2] + 1):
            for y in range(lo[1], hi[1] + 1):
                for x in range(lo[0], hi[0] + 1):
                    want[(x, y, z)] = np.float32(item["value"]).tobytes()
    for box in (None, ((-5, 0, 0), (20, 40, 60))):
        corners, log2, values = g.active_voxels(box)
        got = {}
        for c, l, v in zip(corners, log2, values):
            n = 1 << int(l)
            for z in range(n):
                for y in range(n):
                    for x in range(n):
                        p = (int(c[0]) + x, int(c[1]) + y, int(c[2]) + z)
                        if box is None or all(box[0][a] <= p[a] <= box[1][a] for a in range(3)):
                            got[p] = v.tobytes()
        expected = want if box is None else {p: v for p, v in want.items() if all(box[0][a] <= p[a] <= box[1][a] for a in range(3))}
        assert got == expected
        assert (log2 > 0).any() or box is not None


def test_encode_decode_round_trip_is_exact(work):
    vdb = sphere_file(work)
    path = encoded(work, vdb)
    back = os.path.join(work, "back.vdb")
    vdbdag.decode(path, back)
    for name in ("sphere", "fog", "velocity"):
        a, b = openvdb.read(vdb, name), openvdb.read(back, name)
        ijk = sample_coords(a, 4000, 3)
        va, aa = reference(a, ijk)
        vb, ab = reference(b, ijk)
        assert np.array_equal(aa, ab)
        assert np.array(va).tobytes() == np.array(vb).tobytes()


def test_errors_are_vdbdag_errors(work):
    with pytest.raises(vdbdag.Error, match="missing.ssvdag"):
        vdbdag.open(os.path.join(work, "missing.ssvdag"))
    g = vdbdag.open(encoded(work, sphere_file(work))).grid("sphere")
    with pytest.raises(ValueError):
        g.values(np.zeros((4, 2), dtype=np.int32))
    with pytest.raises(vdbdag.Error):
        vdbdag.open(encoded(work, sphere_file(work))).grid("no such grid")
    with pytest.raises(vdbdag.Error):
        vdbdag.encode(os.path.join(work, "missing.vdb"), os.path.join(work, "x.ssvdag"))
    assert not os.path.exists(os.path.join(work, "x.ssvdag"))


def test_open_refuses_a_file_beyond_its_limits(work):
    """max_voxels and max_memory: pyopenvdb's active voxel count of the
    level set (no tiles) is the threshold; the error names the file."""
    path = encoded(work, sphere_file(work))
    ref = openvdb.read(sphere_file(work), "sphere")
    n = ref.activeVoxelCount()
    with pytest.raises(vdbdag.Error, match="max-voxels") as e:
        vdbdag.open(path, max_voxels=n - 1)
    assert path in str(e.value)
    assert vdbdag.open(path, max_voxels=n).grid("sphere").name == "sphere"
    with pytest.raises(vdbdag.Error, match="max-memory"):
        vdbdag.open(path, max_memory=1024)


def test_lossy_encode_keeps_its_bound(work):
    vdb = sphere_file(work)
    out = os.path.join(work, "lossy.ssvdag")
    report = vdbdag.encode(vdb, out, abs_error=0.01, grid=["sphere"])
    ref = openvdb.read(vdb, "sphere")
    g = vdbdag.open(out).grid("sphere")
    ijk = sample_coords(ref, 10000, 9)
    want, active = reference(ref, ijk)
    got = g.values(ijk)
    assert np.array_equal(g.is_active(ijk), active)
    measured = np.max(np.abs(got[active] - np.array(want, dtype=np.float32)[active]))
    assert measured <= 0.01
    # The report, as a dict: the file's size on disk, the grid's active
    # voxel count as pyopenvdb counts it, and an error bound that covers
    # what the lookups measured.
    assert report["bytes"] == os.path.getsize(out)
    assert report["grids"][0]["name"] == "sphere"
    assert report["grids"][0]["active_voxels"] == ref.activeVoxelCount()
    (lossy,) = report["grids_lossy"]
    assert measured <= lossy["max_abs_error"] <= 0.01
    back = os.path.join(work, "lossy_back.vdb")
    assert isinstance(vdbdag.decode(out, back), dict)
    assert os.path.exists(back)


@pytest.mark.skipif(not os.path.exists(os.path.join(SHARED, "levelsets", "bunny_d512_ls.vdb")), reason="../shared/data absent")
def test_bunny_level_set_100000_lookups(work):
    vdb = os.path.join(SHARED, "levelsets", "bunny_d512_ls.vdb")
    path = encoded(work, vdb)
    name = vdbdag.open(path).grids[0].name
    check_grid(vdb, path, name, 100000, seed=2)


def test_sequence_frames_equal_pyopenvdb(work):
    """A cache of three frames (spheres growing, numbered 10, 11, 13) in one
    file: File.frames() gives the numbers, grid(name, frame) each frame's
    values, and decode writes each frame back."""
    radii = {10: 12.0, 11: 13.5, 13: 15.0}
    for number, radius in radii.items():
        ls = openvdb.createLevelSetSphere(radius=radius, center=(1.0, 2.0, 3.0), voxelSize=0.5, halfWidth=3.0)
        ls.name = "surface"
        openvdb.write(os.path.join(work, "cache.%04d.vdb" % number), grids=[ls])
    seq = os.path.join(work, "cache.ssvdag")
    vdbdag.encode(os.path.join(work, "cache.####.vdb"), seq)
    f = vdbdag.open(seq)
    assert f.is_sequence
    assert [number for number, _ in f.frames()] == [10, 11, 13]
    for number, grids in f.frames():
        assert [g.name for g in grids] == ["surface"]
        ref = openvdb.read(os.path.join(work, "cache.%04d.vdb" % number), "surface")
        ijk = sample_coords(ref, 2000, number)
        want_values, want_active = reference(ref, ijk)
        g = f.grid("surface", frame=number)
        assert np.array_equal(g.is_active(ijk), want_active)
        assert g.values(ijk).tobytes() == np.array(want_values, dtype=np.float32).tobytes()
    with pytest.raises(vdbdag.Error, match="no frame 12"):
        f.grid("surface", frame=12)
    vdbdag.decode(seq, os.path.join(work, "back.%04d.vdb"), frames="11")
    back = openvdb.read(os.path.join(work, "back.0011.vdb"), "surface")
    assert back.activeVoxelCount() == openvdb.read(os.path.join(work, "cache.0011.vdb"), "surface").activeVoxelCount()
    assert not os.path.exists(os.path.join(work, "back.0010.vdb"))


ATLASES = ["AICHAmc", "HarvardOxford-cort-maxprob-thr0-1mm", "labels256", "torsoLabel"]


@pytest.mark.parametrize("name", ATLASES)
def test_atlas_every_voxel_equals_nibabel(name, work):
    """A label atlas of ../shared, encoded in process (its windows coded as
    labels, window coding 17), read back by the reader library: every voxel
    equal to nibabel's array of the source, and every voxel active."""
    nib = pytest.importorskip("nibabel")
    src = os.path.join(SHARED, "medical", "nifti", name + ".nii.gz")
    if not os.path.exists(src):
        pytest.skip(f"no {src}")
    out = os.path.join(work, name + ".ssvdag")
    vdbdag.encode(src, out)
    want = np.asanyarray(nib.load(src).dataobj)
    g = vdbdag.open(out).grids[0]
    (x0, y0, z0), (x1, y1, z1) = g.index_bbox
    assert (x0, y0, z0) == (0, 0, 0) and (x1 + 1, y1 + 1, z1 + 1) == want.shape
    got = np.asarray(g.dense([[0, 0, 0], [x1, y1, z1]]))  # x, y, z as nibabel's
    assert got.shape == want.shape
    assert np.array_equal(got.astype(np.int64), want.astype(np.int64))
    assert g.active_voxel_count == want.size
