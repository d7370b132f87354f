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
// brick order, each brick's voxels in bit order x + 4y + 16z). With
// `tiles`, each aligned 8^3 block inside the box whose 512 labels are one
// is a tile instead of its 8 bricks (as a scan's import makes it).
template <typename Label>
GridRecord labelBox(const std::string& name, int bricksX, int bricksY, int bricksZ, Label&& label, bool tiles = false) {
    GridRecord labels;
    labels.name = name;
    labels.valueType = ValueType::Int32;
    labels.background = {0, 0, 0, 0};
    const auto put = [](std::vector<uint8_t>& to, int32_t v) {
        const auto* p = reinterpret_cast<const uint8_t*>(&v);
        to.insert(to.end(), p, p + 4);
    };
    const auto solid = [&](int x0, int y0, int z0) {
        if (!tiles || x0 % 8 || y0 % 8 || z0 % 8 || x0 + 8 > 4 * bricksX || y0 + 8 > 4 * bricksY || z0 + 8 > 4 * bricksZ) return false;
        for (int k = 0; k < 512; ++k)
            if (label(x0 + (k & 7), y0 + ((k >> 3) & 7), z0 + (k >> 6)) != label(x0, y0, z0)) return false;
        return true;
    };
    for (int bz = 0; bz < bricksZ; ++bz)
        for (int by = 0; by < bricksY; ++by)
            for (int bx = 0; bx < bricksX; ++bx) {
                const int x = 4 * bx, y = 4 * by, z = 4 * bz;
                if (solid(x & ~7, y & ~7, z & ~7)) {
                    if (x % 8 == 0 && y % 8 == 0 && z % 8 == 0) {
                        labels.topology.tiles.push_back({x, y, z, 3});
                        put(labels.values.tiles, label(x, y, z));
                    }
                    continue;
                }
                labels.topology.bricks.push_back({x, y, z, ~uint64_t(0)});
                for (int k = 0; k < 64; ++k) put(labels.values.bricks, label(x + (k & 3), y + ((k >> 2) & 3), z + (k >> 4)));
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
