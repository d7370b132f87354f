// The index bounding box of a compact DAG's voxels, bottom-up: one visit
// per stored node, its children's boxes reflected and offset into its own
// frame, so the cost is that of the DAG as stored, not of the voxels.
#pragma once
#include <array>
#include <cstdint>
#include <optional>

#include "src/encoding/CompactDag.h"

namespace vdbdag::format {

struct IndexBox {
    std::array<int64_t, 3> min{}, max{};  // inclusive, as OpenVDB's CoordBBox
};

// The bounding box of every voxel the DAG holds (bricks and solid nodes);
// empty for an empty DAG.
std::optional<IndexBox> dagBounds(const encoding::CompactDag& dag);

} // namespace vdbdag::format
