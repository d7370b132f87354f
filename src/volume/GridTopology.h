// The active topology of one grid, as the DAG builder consumes it: 4^3 bricks
// (one 64-bit mask each) plus active tiles, which are never expanded into
// voxels (DESIGN.md invariant 4). Coordinates are OpenVDB index coordinates
// (signed 32-bit), so this header needs no OpenVDB.
#pragma once
#include <cstdint>
#include <vector>

namespace vdbdag {

// Bit (x + 4*y + 16*z) of `mask` is voxel (origin + (x,y,z)), x,y,z in 0..3.
inline constexpr int brickBitIndex(int x, int y, int z) { return x | (y << 2) | (z << 4); }

struct Brick {
    int32_t x, y, z;  // minimum corner, each a multiple of 4
    uint64_t mask;    // never 0
};

// An active tile: the cube [x, x + 2^log2Size)^3, aligned to its size
// (OpenVDB tiles are 8, 128 or 4096 voxels wide).
struct Tile {
    int32_t x, y, z;
    uint8_t log2Size;  // >= 3
};

struct GridTopology {
    std::vector<Brick> bricks;  // any order, no two with the same corner
    std::vector<Tile> tiles;    // disjoint from each other and from the bricks

    bool empty() const { return bricks.empty() && tiles.empty(); }
    // Number of active voxels, tiles counted as their voxels (may exceed 2^64
    // only in theory: a grid spans at most 2^96 voxels, so we saturate).
    uint64_t activeVoxelCount() const;
};

} // namespace vdbdag
