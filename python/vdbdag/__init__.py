"""Read .ssvdag files (attributed symmetry-aware sparse voxel DAGs) with numpy.

    import vdbdag, numpy as np
    f = vdbdag.open("bunny.ssvdag")
    g = f.grids[0]                       # g.name, g.value_type, g.active_voxel_count, g.index_bbox
    v = g.values(np.array([[0, 0, 0], [10, 2, 3]], dtype=np.int32))
    block = g.dense(((0, 0, 0), (63, 63, 63)))
    vdbdag.encode("in.vdb", "out.ssvdag", abs_error=0.01)
    vdbdag.decode("out.ssvdag", "back.vdb")

encode and decode run in this process, through the library the vdbdag
command is built from (no executable is needed; the module that does it,
vdbdag._codec, is loaded on the first call). Each returns the report the
command prints with --json (a dict: bytes written, seconds, per-grid facts
and, for a lossy encode, the errors measured; "warnings" and "notes" hold
what the command would print on stderr) and raises vdbdag.Error with the
command's one-line message for a refused input, output or option.
"""
from ._vdbdag import Error, File, Grid, format_version, open  # noqa: F401

__all__ = ["Error", "File", "Grid", "format_version", "open", "encode", "decode"]


def _coder():
    from . import _codec as codec  # OpenVDB and GDCM load here, not on import

    return codec


def encode(src, dst=None, **options):
    """Encodes src (.vdb, .nvdb, a dense scan, a DICOM series, NIfTI, ...) into the .ssvdag dst.

    src is a path or a list of paths, as the command's inputs: several DICOM
    files or folders are one series; a frame pattern ("smoke.####.vdb"), a
    folder of .vdb frames, or a list with dst "NAME.ssvdag" make one
    sequence file; other lists one file each, in the folder dst names.
    dst None: the input's name with .ssvdag, beside it.
    Keyword options are the command's: abs_error=0.01 -> --abs-error 0.01,
    force=True -> --force, grid=["a", "b"] -> --grid a --grid b,
    memory_limit="512M" (or a number of bytes), dims=(256, 256, 99).
    Returns the report, as `vdbdag encode --json` prints it (a dict: "bytes",
    "seconds", "grids", "grids_lossy" with each lossy grid's errors, ...;
    a list of them for one file each).
    """
    return _coder().encode(src, dst, **options)


def decode(src, dst, **options):
    """Decodes the .ssvdag src into dst (.vdb, .nvdb, or a dense format by its extension).

    Options: force, grid (a scan output's grid), stored_values, frames ("12",
    "10-20", "1,5,9-12": a sequence file's frames, each to dst with its
    number in the frame token, out.####.vdb), max_voxels, max_memory.
    Returns the report, as `vdbdag decode --json` prints it (a dict, or a
    list of the frames' reports).
    """
    return _coder().decode(src, dst, **options)
