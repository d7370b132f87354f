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
    // Try this many root placements (DESIGN.md invariant 1) and keep the one
    // whose geometry sections are smallest in the file (compressed as the
    // writer stores them); 1 = the bounding box's aligned minimum only.
    int placementTrials = 1;
    // 16-bit pointers where offsets fit (SSVDAG paper §4.3); false: all 32-bit.
    bool compactPointers = true;
    // Lossy scalar values (float/double active values only; inactive values
    // and other types stay exact). The report lands in EncodedGrid::lossy.
    attributes::ScalarTolerance tolerance;
    // Lossy colours (ColourQuantizer.h): 0 = exact; else at most 2^colourBits
    // colours per colour grid. Colour grids: vec3 grids named in
    // `colourGrids`, or when that is empty, vec3 grids with a colour name
    // (hasColourGridName). Inactive values stay exact.
    unsigned colourBits = 0;
    std::vector<std::string> colourGrids;
    // k-bit ONV normals (NormalChannel.h) for grids whose record carries
    // exact normals (GridRecord::normals); 0 = none stored.
    unsigned normalBits = 0;
    // Integer (int32/int64) channels: also code the values with the brick
    // predictor (attributes/PredictedChannel.h) and store whichever of
    // palettes and residuals zstd makes smaller.
    bool predictIntegers = true;
    // A grid in memory (encodeGrid, encodeVolume...): the encoded grid also
    // holds its values in attribute order (EncodedGrid::attributes, as a
    // file read whole does), for callers that read them (`info`'s channel
    // statistics, `render`'s label test). Callers that only write the file
    // or read it back (encode, verify, bench) turn it off: a layer streamed
    // into windows is not gathered, nor a lossy one decoded, once more.
    bool keepAttributes = true;
    // Called as each step of a grid starts (kEncodeSteps per grid), for progress.
    std::function<void(const char* step)> onStep;
    // Within a step of the cube-by-cube encoder: cubes done of the pass's total.
    std::function<void(uint64_t done, uint64_t total)> onStepProgress;
};
inline constexpr int kEncodeSteps = 4;

// Whether `grid` is quantised as colours under `options`.
bool isColourGrid(const GridRecord& grid, const EncodeOptions& options);

// A grid in memory: the cube-by-cube encoder (CubeEncoder.h, the one
// encoder) over the grid sliced into cubes (recordCubes), normals included.
format::EncodedGrid encodeGrid(const GridRecord& grid, const EncodeOptions& options = {});
GridRecord decodeGrid(const format::EncodedGrid& grid);

// Whole volumes; `onGrid(index, count)` is called before each grid (progress).
using GridProgress = std::function<void(size_t index, size_t count)>;
format::SsvdagScene encodeVolume(const Volume& volume, const EncodeOptions& options = {}, const GridProgress& onGrid = {});
// The same, releasing each grid (voxels and header) as soon as it is
// encoded: the grids are empty afterwards.
format::SsvdagScene encodeVolumeReleasing(Volume& volume, const EncodeOptions& options = {}, const GridProgress& onGrid = {});
Volume decodeScene(const format::SsvdagScene& scene, const GridProgress& onGrid = {});

} // namespace vdbdag::pipeline
