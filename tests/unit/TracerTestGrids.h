// Test grids shared by the CPU and Vulkan tracer tests: a validated compact
// DAG from a topology, and random topologies of tiles and bricks (some of
// them mirror images of each other, so symmetry merges them).
#pragma once
#include <random>

#include "src/dag/DagBuilder.h"
#include "src/encoding/CompactDag.h"

namespace vdbdag::testing {

inline encoding::CompactDag compactOf(const GridTopology& topology, bool symmetry = true) {
    dag::BuildOptions options;
    options.symmetry = symmetry;
    encoding::CompactDag dag = encoding::encodeCompact(dag::buildDag(topology, options), true);
    encoding::validateCompact(dag, "test dag");
    return dag;
}

// Random 8^3 cells: empty, an active 8^3 tile, or up to 8 random bricks.
inline GridTopology randomTopology(std::mt19937_64& rng, int cells, int32_t corner = 0) {
    GridTopology topology;
    std::uniform_int_distribution<int> kind(0, 9);
    for (int cz = 0; cz < cells; ++cz)
        for (int cy = 0; cy < cells; ++cy)
            for (int cx = 0; cx < cells; ++cx) {
                const int k = kind(rng);
                const int32_t x = corner + 8 * cx, y = corner + 8 * cy, z = corner + 8 * cz;
                if (k <= 4) continue;
                if (k == 5) { topology.tiles.push_back({x, y, z, 3}); continue; }
                for (int b = 0; b < 8; ++b) {
                    if (rng() % 3 == 0) continue;
                    uint64_t mask = rng() & rng() & rng();
                    if (b >= 4 && (rng() & 1)) mask = 0x0000000000000F01ull << (rng() % 4);
                    if (!mask) mask = 1;
                    topology.bricks.push_back({x + 4 * (b & 1), y + 4 * ((b >> 1) & 1), z + 4 * (b >> 2), mask});
                }
            }
    return topology;
}

} // namespace vdbdag::testing
