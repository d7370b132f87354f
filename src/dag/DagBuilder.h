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

} // namespace vdbdag::dag
