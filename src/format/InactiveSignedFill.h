// A grid whose inactive layer is OpenVDB's signed flood fill of its active
// values (EncodedGrid::inactiveSignedFill; docs/FORMAT.md 6.6) stores no
// inactive layer: the reader makes it again here, from the active layer,
// with src/volume/SignedFill.h, as the layer an encoder would have stored
// (its DAG built afresh, every value -|background|).
#pragma once
#include <string>

#include "src/attributes/ValueWindows.h"
#include "src/format/SsvdagFile.h"
#include "src/volume/SignedFill.h"

namespace vdbdag::format {

// Sets grid.inactive from grid.active (whose DAG and values are read: as
// attributes, a palette channel or value windows, decoded through
// `parallel`). Throws vdbdag::Error starting with `what` when the fill does
// not apply to the grid or gives another voxel count than the file says
// (grid.inactive.voxels, from GridInfo): the file is corrupt.
void restoreSignedFill(EncodedGrid& grid, const attributes::ParallelFor& parallel, const std::string& what);

// The fill itself, from the active voxels `active` with `values` (in
// GridRecord's order) of `grid`, checked as restoreSignedFill checks it:
// for a reader that has the active voxels decoded already and needs no DAG
// of the inside (pipeline::decodeGrid, of a scene read without
// ReadOptions::signedFillLayer).
InactiveLayer signedFillOf(const EncodedGrid& grid, const GridTopology& active, const LayerValues& values, const attributes::ParallelFor& parallel,
                           const std::string& what);

} // namespace vdbdag::format
