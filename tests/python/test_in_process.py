"""vdbdag.encode and vdbdag.decode run in the Python process (vdbdag._codec),
with no vdbdag executable anywhere: checked in a child interpreter whose
PATH holds no vdbdag and whose VDBDAG_EXECUTABLE names a file that does not
exist. References: pyopenvdb's accessor for .vdb round trips, numpy for a
raw scan's samples (written here, read back from the decoded .raw), and the
command's own bytes for the same request (the two callers of one library
must agree)."""
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import vdbdag

openvdb = pytest.importorskip("pyopenvdb")


def sphere(work):
    path = os.path.join(work, "sphere.vdb")
    if not os.path.exists(path):
        ls = openvdb.createLevelSetSphere(radius=20.0, center=(1.5, -2.0, 3.0), voxelSize=0.5, halfWidth=3.0)
        ls.name = "sphere"
        openvdb.write(path, grids=[ls])
    return path


CHILD = r"""
import json, os, shutil, sys
import vdbdag
assert shutil.which("vdbdag") is None, shutil.which("vdbdag")
src, work = sys.argv[1], sys.argv[2]
enc = vdbdag.encode(src, os.path.join(work, "child.ssvdag"))
dec = vdbdag.decode(os.path.join(work, "child.ssvdag"), os.path.join(work, "child_back.vdb"))
print(json.dumps({"enc": enc, "dec": dec, "pid": os.getpid()}))
"""


def test_encode_and_decode_need_no_executable(work):
    src = sphere(work)
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": os.pathsep.join(p for p in sys.path if p), "VDBDAG_EXECUTABLE": os.path.join(work, "no-such-vdbdag")}
    if shutil.which("vdbdag", path=env["PATH"]):
        pytest.skip("a vdbdag command is installed in /usr/bin")
    out = subprocess.run([sys.executable, "-c", CHILD, src, work], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    reports = json.loads(out.stdout)
    assert reports["enc"]["bytes"] == os.path.getsize(os.path.join(work, "child.ssvdag"))
    assert reports["enc"]["warnings"] == [] and isinstance(reports["enc"]["notes"], list)
    assert reports["dec"]["output"] == os.path.join(work, "child_back.vdb")
    a, b = openvdb.read(src, "sphere"), openvdb.read(os.path.join(work, "child_back.vdb"), "sphere")
    assert a.activeVoxelCount() == b.activeVoxelCount()
    ca, cb = a.getConstAccessor(), b.getConstAccessor()
    for item in a.citerOnValues():
        assert cb.probeValue(item.min) == ca.probeValue(item.min)


def test_same_bytes_as_the_command(work):
    exe = os.environ.get("VDBDAG_EXECUTABLE")
    if not exe or not os.access(exe, os.X_OK):
        pytest.skip("VDBDAG_EXECUTABLE not set (ctest sets it)")
    src = sphere(work)
    ours = os.path.join(work, "python.ssvdag")
    theirs = os.path.join(work, "command.ssvdag")
    report = vdbdag.encode(src, ours, abs_error=0.02, no_symmetry=True, threads=1)
    subprocess.run([exe, "encode", src, "-o", theirs, "--abs-error", "0.02", "--no-symmetry", "--threads", "1", "-q"], check=True)
    with open(ours, "rb") as a, open(theirs, "rb") as b:
        assert a.read() == b.read()
    (lossy,) = report["grids_lossy"]
    assert 0 < lossy["max_abs_error"] <= 0.02


def test_normals_keep_to_a_memory_limit(work):
    """--normals on a .vdb read region by region (memory_limit): the same
    bytes as without a limit, and the one-sided count equals the active
    voxels that pyopenvdb finds with an inactive neighbour on some axis."""
    src = sphere(work)
    whole, limited = os.path.join(work, "normals.ssvdag"), os.path.join(work, "normals_16M.ssvdag")
    report = vdbdag.encode(src, whole, normals=16)
    vdbdag.encode(src, limited, normals=16, memory_limit="16M", threads=1)
    with open(whole, "rb") as a, open(limited, "rb") as b:
        assert a.read() == b.read()
    grid = openvdb.read(src, "sphere")
    acc = grid.getConstAccessor()
    edges = 0
    for item in grid.citerOnValues():
        x, y, z = item.min
        around = [(x + 1, y, z), (x - 1, y, z), (x, y + 1, z), (x, y - 1, z), (x, y, z + 1), (x, y, z - 1)]
        edges += not all(acc.isValueOn(c) for c in around)
    (normals,) = report["grids_normals"]
    assert normals["entries"] == grid.activeVoxelCount()
    assert normals["one_sided"] == edges > 0
    assert normals["max_angle_degrees"] <= 0.95  # the 16-bit ONV bound


def test_raw_scan_options_round_trip_against_numpy(work):
    """dims, type, endian and spacing as keywords; the big-endian int16
    samples come back from the decoded little-endian .nhdr's data as numpy
    wrote them."""
    rng = np.random.default_rng(7)
    samples = rng.integers(-900, 2500, size=(5, 7, 9), dtype=np.int16)  # z, y, x
    raw = os.path.join(work, "scan.raw")
    samples.astype(">i2").tofile(raw)
    enc = os.path.join(work, "scan.ssvdag")
    report = vdbdag.encode(raw, enc, dims=(9, 7, 5), type="i16", endian="big", spacing=[0.5, 0.5, 2.0])
    assert report["active_voxels"] == samples.size
    out = os.path.join(work, "scan_back.raw")
    vdbdag.decode(enc, out, force=True)
    back = np.fromfile(out, dtype="<i2").reshape(samples.shape)
    assert np.array_equal(back, samples)
    g = vdbdag.open(enc).grids[0]
    assert np.allclose(np.diag(g.index_to_world)[:3], [0.5, 0.5, 2.0])


def test_refusals(work):
    src = sphere(work)
    target = os.path.join(work, "refused.ssvdag")
    with pytest.raises(TypeError, match="unexpected keyword argument 'abs_eror'"):
        vdbdag.encode(src, target, abs_eror=0.1)
    with pytest.raises(vdbdag.Error, match="placement_trials"):
        vdbdag.encode(src, target, placement_trials=65)
    with pytest.raises(vdbdag.Error, match="exclude each other"):
        vdbdag.encode(src, target, abs_error=0.1, rel_error=0.01)
    with pytest.raises(vdbdag.Error, match="threads: 2.5 is not a whole number"):
        vdbdag.encode(src, target, threads=2.5)
    with pytest.raises(vdbdag.Error, match="normals: -3"):
        vdbdag.encode(src, target, normals=-3)
    with pytest.raises(vdbdag.Error, match="not a size"):
        vdbdag.encode(src, target, memory_limit="12Q")
    with pytest.raises(vdbdag.Error, match="--dims"):
        vdbdag.encode(src, target, dims=(2, 2, 2))
    with pytest.raises(vdbdag.Error, match="frames applies to sequence files"):
        vdbdag.decode(vdbdag.encode(src, target)["output"], os.path.join(work, "x.vdb"), frames="3")
    os.remove(target)
    assert not os.path.exists(target) and not os.path.exists(os.path.join(work, "x.vdb"))
    assert [f for f in os.listdir(work) if f.startswith(".") or f.endswith(".tmp")] == []


def test_bytes_paths_and_one_file_each(work):
    """Paths as bytes (os.fsencode) read as the str; several inputs one
    file each give a list of reports, each with its own notes."""
    src = sphere(work)
    out = os.path.join(work, "bytes.ssvdag")
    report = vdbdag.encode(os.fsencode(src), os.fsencode(out))
    assert report["output"] == out and os.path.getsize(out) == report["bytes"]
    other = os.path.join(work, "sphere2.vdb")
    shutil.copyfile(src, other)
    folder = os.path.join(work, "each")
    reports = vdbdag.encode([src, other], folder)
    assert isinstance(reports, list) and len(reports) == 2
    for r in reports:
        assert os.path.getsize(r["output"]) == r["bytes"]
        assert isinstance(r["warnings"], list) and isinstance(r["notes"], list)
