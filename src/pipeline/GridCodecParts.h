// The steps of encodeGrid that the cube-by-cube encoder (CubeEncoder.h)
// shares, so both give the same bytes: root placement candidates, DAG
// statistics, the grid header and the coding of gathered values.
#pragma once
#include <array>
#include <functional>
#include <vector>

#include "src/dag/DagBuilder.h"
#include "src/pipeline/GridCodec.h"

namespace vdbdag::pipeline {

// Root origins to try for a layer with this box and tile alignment
// (placementAlignment), best guesses first; `trials` of them at most.
std::vector<std::array<int64_t, 3>> placementCandidates(const dag::ActiveBounds& box, int64_t alignment, int trials);

format::DagStats statsOf(const dag::ReducedDag& reduced);

// Builds a layer at each placement candidate and keeps the smallest compact
// encoding; with `stats`, also the plain SVDAG's node counts at the kept
// placement when options.computeSvdagStats. `build(origin, symmetry)`
// builds the layer's DAG with its root at `origin`.
using PlacedBuild = std::function<dag::ReducedDag(const std::array<int64_t, 3>& origin, bool symmetry)>;
encoding::CompactDag encodeAtBestPlacement(const dag::ActiveBounds& box, int64_t alignment, const EncodeOptions& options, bool withOffsets,
                                           format::DagStats* stats, const PlacedBuild& build, std::array<int64_t, 3>* keptOrigin = nullptr);

// An EncodedGrid with `grid`'s header and nothing else.
format::EncodedGrid encodedHeader(const GridRecord& grid, const EncodeOptions& options);

// Whether a channel of `type` is stored in predicted windows (integers,
// unless --no-predict) rather than palette windows.
bool usesPredictedWindows(ValueType type, const EncodeOptions& options);

// From out.attributes / out.inactiveAttributes (attribute order): the lossy
// settings, then the value windows (predicted windows for integers).
void codeActiveValues(format::EncodedGrid& out, const EncodeOptions& options);
void codeInactiveValues(format::EncodedGrid& out, const EncodeOptions& options);

} // namespace vdbdag::pipeline
