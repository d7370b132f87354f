"""Read .ssvdag files (attributed symmetry-aware sparse voxel DAGs) with numpy.

    import vdbdag, numpy as np
    f = vdbdag.open("bunny.ssvdag")
    g = f.grids[0]                       # g.name, g.value_type, g.active_voxel_count, g.index_bbox
    v = g.values(np.array([[0, 0, 0], [10, 2, 3]], dtype=np.int32))
    block = g.dense(((0, 0, 0), (63, 63, 63)))
    vdbdag.encode("in.vdb", "out.ssvdag", abs_error=0.01)
    vdbdag.decode("out.ssvdag", "back.vdb")

encode and decode run the vdbdag command: $VDBDAG_EXECUTABLE, else the one
installed beside this package's prefix, else vdbdag on the PATH. Each
returns the command's report (its --json output) as a dict: bytes written,
seconds, per-grid facts and, for a lossy encode, the errors measured.
"""
import json
import os
import shutil
import subprocess

from ._vdbdag import Error, File, Grid, format_version, open  # noqa: F401

__all__ = ["Error", "File", "Grid", "format_version", "open", "encode", "decode"]


def _executable():
    env = os.environ.get("VDBDAG_EXECUTABLE")
    if env:
        return env
    here = os.path.dirname(os.path.abspath(__file__))
    # <prefix>/lib/python3/dist-packages/vdbdag -> <prefix>/bin/vdbdag
    for up in (3, 4):
        candidate = os.path.join(here, *([".."] * up), "bin", "vdbdag")
        if os.access(candidate, os.X_OK):
            return os.path.normpath(candidate)
    found = shutil.which("vdbdag")
    if not found:
        raise Error("the vdbdag command was not found: set VDBDAG_EXECUTABLE or put vdbdag on the PATH")
    return found


def _run(arguments):
    result = subprocess.run([_executable(), *arguments, "--quiet", "--json"], capture_output=True, text=True)
    if result.returncode != 0:
        message = (result.stderr.strip().splitlines() or ["vdbdag exited with status %d" % result.returncode])[-1]
        raise Error(message)
    try:
        return json.loads(result.stdout)
    except ValueError:
        raise Error("vdbdag printed no report: " + result.stdout[:200])


def _flags(options):
    out = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            out.append(flag)
        elif value is False or value is None:
            continue
        elif isinstance(value, (list, tuple)):
            for item in value:
                out += [flag, str(item)]
        else:
            out += [flag, str(value)]
    return out


def encode(src, dst, **options):
    """Encodes src (.vdb, a dense scan, a DICOM series, NIfTI, ...) into the .ssvdag dst.

    Keyword options are the command's: abs_error=0.01 -> --abs-error 0.01,
    force=True -> --force, grid=["a", "b"] -> --grid a --grid b.
    Returns the report, as `vdbdag encode --json` prints it (a dict: "bytes",
    "seconds", "grids", "grids_lossy" with each lossy grid's errors, ...).
    """
    return _run(["encode", os.fspath(src), "-o", os.fspath(dst), *_flags(options)])


def decode(src, dst, **options):
    """Decodes the .ssvdag src into dst (.vdb, or a dense format by its extension).

    Returns the report, as `vdbdag decode --json` prints it (a dict).
    """
    return _run(["decode", os.fspath(src), "-o", os.fspath(dst), *_flags(options)])
