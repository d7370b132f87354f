// Morton (Z-order) comparison of 3D cell coordinates without building the
// interleaved key (which would need 96 bits for VDB's whole index range).
// In Morton order the 8 children of every node are contiguous at every
// level, which is what the bottom-up DAG builder groups on.
#pragma once
#include <cstdint>

namespace vdbdag::dag {

struct CellCoord {
    uint32_t x, y, z;
    bool operator==(const CellCoord&) const = default;
};

// True when the highest set bit of a is below the highest set bit of b.
constexpr bool msbBelow(uint32_t a, uint32_t b) { return a < b && a < (a ^ b); }

// Interleaving order z_k y_k x_k ... z_0 y_0 x_0 (x varies fastest), which
// matches child slot x | y<<1 | z<<2.
constexpr bool mortonLess(const CellCoord& a, const CellCoord& b) {
    uint32_t best = a.z ^ b.z;
    int axis = 2;
    if (msbBelow(best, a.y ^ b.y)) { best = a.y ^ b.y; axis = 1; }
    if (msbBelow(best, a.x ^ b.x)) { best = a.x ^ b.x; axis = 0; }
    return axis == 0 ? a.x < b.x : axis == 1 ? a.y < b.y : a.z < b.z;
}

constexpr unsigned childSlot(const CellCoord& c) { return (c.x & 1u) | ((c.y & 1u) << 1) | ((c.z & 1u) << 2); }
constexpr CellCoord parentCell(const CellCoord& c) { return {c.x >> 1, c.y >> 1, c.z >> 1}; }

} // namespace vdbdag::dag
