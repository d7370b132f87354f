// A series' previous volume as the reference of its values (issue 43 item
// 2; docs/CODING.md "A series' previous volume as neighbours"): the
// encoder's last pass over a scene whose grids are the volumes of one 4-D
// scan (an fMRI, ASL, DCE or DWI series: one grid a volume, the same voxels
// in each). Grid g's windows are coded again with grid g - 1's same window
// as four more neighbours of every voxel (window codings 21 and 22), and
// each keeps whichever of its two codings is smaller; the grid then
// carries a ValueReference section (docs/FORMAT.md 8.6) that names grid
// g - 1.
//
// A reader of grid g decodes grid g - 1's window first, and that one's
// reference before it: a key grid every `keyEvery` grids of a run refers
// to none, so no grid needs more than keyEvery - 1 others decoded.
//
// Which grids: those whose active DAG is the grid before's (entry for
// entry the same layout), of the same value type, with their values in
// predicted windows and coded lossless. The pass runs on the finished
// scene, so its bytes do not depend on how the scene was built (threads,
// --memory-limit, mpirun).
#pragma once
#include <cstdint>

#include "src/format/SsvdagFile.h"

namespace vdbdag::pipeline {

// The default distance between key grids: a reader decodes at most 7 other
// volumes of a series to reach one (mpld_asl.nii.gz: docs/CODING.md).
inline constexpr unsigned kDefaultKeyEvery = 8;

struct SeriesReferenceReport {
    uint64_t referencedGrids = 0, referencedWindows = 0;
    uint64_t bytesBefore = 0, bytesAfter = 0;  // the active windows of the grids tried
};

// Codes every eligible grid of `scene` against the one before (above);
// `keyEvery` 1 (none is referenced) to kMaxReferenceChain + 1. A grid's
// decoded windows are kept for the next grid when they take at most
// `keepBytes` (else that grid decodes them again: the same bytes either
// way). Throws vdbdag::Error on an internal inconsistency only.
SeriesReferenceReport referenceSeries(format::SsvdagScene& scene, unsigned keyEvery = kDefaultKeyEvery, uint64_t keepBytes = uint64_t(256) << 20);

} // namespace vdbdag::pipeline
