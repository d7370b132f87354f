// An OpenVDB leaf's 8^3 voxel mask as eight 64-bit words (leaf voxel
// n = x << 6 | y << 3 | z is bit (y << 3 | z) of word x, NodeMask<3>'s own
// layout) and its eight 4^3 bricks (brick b's corner at 4 * (b & 1, b >> 1 & 1,
// b >> 2), brick bit x + 4y + 16z brick-relative). Shared by the .vdb
// readers (vdb_bridge/detail/LeafBricks.h) and the signed fill (SignedFill.h).
#pragma once
#include <cstdint>

namespace vdbdag {

// Spreads the 4 bits of a z-row nibble to brick bits 0, 16, 32, 48.
inline constexpr uint64_t spreadZ(unsigned nibble) {
    return uint64_t(nibble & 1u) | (uint64_t((nibble >> 1) & 1u) << 16) | (uint64_t((nibble >> 2) & 1u) << 32) | (uint64_t((nibble >> 3) & 1u) << 48);
}

// Brick b's voxels among the leaf mask's.
inline uint64_t brickOfLeafMask(const uint64_t words[8], unsigned b) {
    const unsigned bx = (b & 1u) * 4, by = ((b >> 1) & 1u) * 4, bz = ((b >> 2) & 1u) * 4;
    uint64_t mask = 0;
    for (unsigned xi = 0; xi < 4; ++xi) {
        const uint64_t word = words[bx + xi];
        if (!word) continue;
        for (unsigned yi = 0; yi < 4; ++yi) mask |= spreadZ(unsigned(word >> (((by + yi) << 3) | bz)) & 0xFu) << (xi + 4 * yi);
    }
    return mask;
}

} // namespace vdbdag
