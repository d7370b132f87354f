// What the encoder (CubeEncoder.h) does with one layer once its geometry is
// built: the root placements to try and the one kept (the smallest file),
// the DAG statistics, the grid header, and the coding of the layer's values
// in attribute order (lossy settings, then value windows).
#pragma once
#include <array>
#include <functional>
#include <optional>
#include <vector>

#include "src/attributes/PredictedWindows.h"
#include "src/dag/DagBuilder.h"
#include "src/pipeline/GridCodec.h"

namespace vdbdag::pipeline {

// Root origins to try for a layer with this box and tile alignment
// (placementAlignment), best guesses first; `trials` of them at most. The
// encoder (CubeEncoder.cpp) builds the layer at each and keeps the smallest
// file.
std::vector<std::array<int64_t, 3>> placementCandidates(const dag::ActiveBounds& box, int64_t alignment, int trials);

format::DagStats statsOf(const dag::ReducedDag& reduced);

// A layer's values as the file stores them, coded in the attribute order of
// one placement candidate.
struct CodedValues {
    std::vector<uint8_t> attributes;  // attribute order, after the lossy settings (empty when streamed)
    attributes::ValueWindowsPayload windows;
    attributes::ToleranceReport lossy;
    std::optional<attributes::ColourReport> colour;
    std::optional<attributes::NormalChannel> normals;
    // What they take in the file: the windows as they are (the container
    // stores them precompressed), the normals as the container compresses them.
    uint64_t storedBytes() const;
};

// An EncodedGrid with `grid`'s header and nothing else.
format::EncodedGrid encodedHeader(const GridRecord& grid, const EncodeOptions& options);

// How a float32 layer of `grid` is predicted, unless --no-predict: its bits
// in 3-D, and a lattice when it has one: GridRecord::rescale when its values
// are kept exactly, the quantiser's multiples of 2E under --abs-error E
// (ScalarTolerance.h; both are float(k x slope + intercept)). An exact
// inactive layer only with a rescale (a level set's are +-background, which
// palettes hold in bytes); a lossy grid's inactive layer never. A vec3s
// active layer that is not a colour grid: its components' bits. Nothing for
// other grids.
std::optional<attributes::FloatChannel> floatChannelOf(const GridRecord& grid, const EncodeOptions& options, bool inactive);
// Whether a layer of `grid` is stored in predicted windows (integers,
// floats as above; unless --no-predict) rather than palette windows.
bool usesPredictedWindows(const GridRecord& grid, const EncodeOptions& options, bool inactive);

// From coded.attributes (attribute order of `dag`): the lossy settings
// (tolerance, colours), then the value windows (predicted windows for
// integers). `header`: the grid's name, type and class.
void codeActiveValues(const encoding::CompactDag& dag, CodedValues& coded, const GridRecord& header, const EncodeOptions& options);
// The same for an inactive layer (never lossy).
void codeInactiveValues(const encoding::CompactDag& dag, CodedValues& coded, const GridRecord& header, const EncodeOptions& options);

// Moves a layer's coded values into `out`.
void storeActiveValues(format::EncodedGrid& out, CodedValues&& coded);
void storeInactiveValues(format::EncodedGrid& out, CodedValues&& coded);

} // namespace vdbdag::pipeline
