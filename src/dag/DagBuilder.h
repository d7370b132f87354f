// Bottom-up construction of the SVDAG / SSVDAG from a grid's active topology
// (SSVDAG paper §4.1, with the invariance handling of DESIGN.md invariant 1).
#pragma once
#include <array>
#include <cstdint>
#include <optional>

#include "src/dag/ReducedDag.h"
#include "src/volume/GridTopology.h"

namespace vdbdag::dag {

struct BuildOptions {
    bool symmetry = true;  // false: plain SVDAG (identical subtrees only)
    // Root placement. By default the root cube's origin is the active
    // bounding box's minimum rounded down to a multiple of the alignment
    // (placementAlignment). An explicit origin must be such a multiple and
    // not above the box's minimum. Placement decides which reflective
    // symmetries exist (DESIGN.md invariant 1).
    std::optional<std::array<int64_t, 3>> origin;
    // Root size (log2 of its width); must cover the active box from the
    // origin. Unset: the smallest that does. Sub-DAGs of a split build
    // (SubDagMerge.h) are all built at the split's cube size.
    std::optional<unsigned> log2Size;
};

// Builds and reduces; unreferenced nodes are dropped, refcounts are exact.
// Deterministic: the result does not depend on the thread count.
ReducedDag buildDag(const GridTopology& topology, const BuildOptions& options = {});

// The alignment the root origin must respect for `topology`: max(4, largest
// tile size), so bricks and tiles fall exactly on nodes.
int64_t placementAlignment(const GridTopology& topology);

// Inclusive index-space bounding box of the active voxels (tiles included).
struct ActiveBounds {
    std::array<int64_t, 3> min, max;
};
ActiveBounds activeBounds(const GridTopology& topology);

// Where the root cube goes for a box and an alignment under `options`
// (origin and log2Size as in BuildOptions). Throws vdbdag::Error if an
// explicit origin or size does not fit.
struct RootPlacement {
    std::array<int64_t, 3> origin;
    unsigned log2Size;
};
RootPlacement placeRoot(const ActiveBounds& box, int64_t alignment, const BuildOptions& options);

} // namespace vdbdag::dag
