// One grid's trip through the core: topology -> reduced DAG -> compact
// encoding (encodeGrid), and back (decodeGrid). No file I/O here.
#pragma once
#include <functional>

#include "src/attributes/ScalarTolerance.h"
#include "src/format/SsvdagFile.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::pipeline {

struct EncodeOptions {
    bool symmetry = true;            // SSVDAG; false = plain SVDAG (same compact encoding)
    bool computeSvdagStats = false;  // also reduce without symmetry, for `info`
    // Try this many root placements (DESIGN.md invariant 1) and keep the
    // smallest encoding; 1 = the bounding box's aligned minimum only.
    int placementTrials = 1;
    // Lossy scalar values (float/double active values only; inactive values
    // and other types stay exact). The report lands in EncodedGrid::lossy.
    attributes::ScalarTolerance tolerance;
    // Integer (int32/int64) channels: also code the values with the brick
    // predictor (attributes/PredictedChannel.h) and store whichever of
    // palettes and residuals zstd makes smaller.
    bool predictIntegers = true;
    // Called as each step of a grid starts (kEncodeSteps per grid), for progress.
    std::function<void(const char* step)> onStep;
};
inline constexpr int kEncodeSteps = 4;

format::EncodedGrid encodeGrid(const GridRecord& grid, const EncodeOptions& options = {});
GridRecord decodeGrid(const format::EncodedGrid& grid);

// Whole volumes; `onGrid(index, count)` is called before each grid (progress).
using GridProgress = std::function<void(size_t index, size_t count)>;
format::SsvdagScene encodeVolume(const Volume& volume, const EncodeOptions& options = {}, const GridProgress& onGrid = {});
// The same, releasing each grid's voxels as soon as they are in attribute
// order (a dense 512x512x999 scan then never holds its values twice); the
// grids keep their headers, their voxels are gone afterwards.
format::SsvdagScene encodeVolumeReleasing(Volume& volume, const EncodeOptions& options = {}, const GridProgress& onGrid = {});
Volume decodeScene(const format::SsvdagScene& scene, const GridProgress& onGrid = {});

} // namespace vdbdag::pipeline
