// Scenes the read-limit tests and the fuzz seed corpus forge alike
// (tests/unit/test_read_limits.cpp, tests/fuzz/make_seed_corpus.cpp; the
// label box also tests/unit/test_tracer.cpp).
#pragma once
#include <cstdint>
#include <string>

#include "src/format/SsvdagFile.h"
#include "src/format/TraceableValues.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::testing {

// A label volume: a box of bricksX x bricksY x bricksZ full 4^3 int32
// bricks from the origin, each voxel holding label(x, y, z) (values in
// brick order, each brick's voxels in bit order x + 4y + 16z).
template <typename Label>
GridRecord labelBox(const std::string& name, int bricksX, int bricksY, int bricksZ, Label&& label) {
    GridRecord labels;
    labels.name = name;
    labels.valueType = ValueType::Int32;
    labels.background = {0, 0, 0, 0};
    for (int bz = 0; bz < bricksZ; ++bz)
        for (int by = 0; by < bricksY; ++by)
            for (int bx = 0; bx < bricksX; ++bx) {
                labels.topology.bricks.push_back({4 * bx, 4 * by, 4 * bz, ~uint64_t(0)});
                for (int k = 0; k < 64; ++k) {
                    const int32_t v = label(4 * bx + (k & 3), 4 * by + ((k >> 2) & 3), 4 * bz + (k >> 4));
                    const auto* p = reinterpret_cast<const uint8_t*>(&v);
                    labels.values.bricks.insert(labels.values.bricks.end(), p, p + 4);
                }
            }
    return labels;
}

// A solid side^3 fog block of full 4^3 bricks (side a multiple of 4), its
// float values all 0 (the caller may set them, in brick order).
inline GridRecord solidFloatBlock(const std::string& name, int side) {
    GridRecord block;
    block.name = name;
    block.gridClass = "fog volume";
    block.valueType = ValueType::Float;
    block.background.assign(4, 0);
    block.vdbDescriptor = {1};
    for (int z = 0; z < side; z += 4)
        for (int y = 0; y < side; y += 4)
            for (int x = 0; x < side; x += 4) block.topology.bricks.push_back({x, y, z, ~uint64_t(0)});
    block.values.bricks.assign(block.topology.bricks.size() * 64 * 4, 0);
    return block;
}

// The grid's values as files before value windows stored them: one palette
// (Values) section, which a reader decodes whole.
inline void useLegacyValues(format::EncodedGrid& grid) {
    grid.active.values = format::traceableValues(grid);
    grid.active.valueWindows = {};
    grid.active.predictedValues.clear();
}

} // namespace vdbdag::testing
