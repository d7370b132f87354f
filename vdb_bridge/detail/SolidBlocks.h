// Which aligned 8^3 blocks of a dense scan are solid: all 512 samples kept
// and one value, bit for bit (so -0.0 is not 0.0 and NaN payloads differ).
// A solid block becomes an active tile, which the DAG stores as a solid node
// with ONE attribute entry instead of 512 (docs/FORMAT.md 6.2): a label
// atlas's regions and a scan's zero-filled background cost one entry per
// block (issue 39 item 1). Shared by the in-memory import (DenseImport.cpp)
// and the cube source (DenseCubes.cpp), so both give the same tiles, and
// decided from the samples alone, never from the cube size: the file is the
// same under every --memory-limit, --threads and mpirun.
//
// Only 8^3 (an OpenVDB leaf's size, and the smallest solid node): larger
// uniform regions are 8^3 tiles side by side, which the DAG already shares
// as one node; merging them would save one entry per 512 voxels at most.
#pragma once
#include <bit>
#include <cstdint>
#include <cstring>
#include <vector>

#include "src/volume/GridTopology.h"

namespace vdbdag::bridge::detail {

inline constexpr int kSolidBlockLog2 = 3;

struct SolidBlocks {
    int64_t cols = 0, rows = 0, slabs = 0;  // blocks along x, y, z (8 wide)
    unsigned valueSize = 0;
    std::vector<uint64_t> solid;  // bit (slab * rows + row) * cols + col
    std::vector<uint8_t> values;  // valueSize bytes per block, in that order (meaningful where solid)
    uint64_t count = 0;           // solid blocks

    // For a scan of cols4 x rows4 x slabs4 bricks.
    void reset(int64_t cols4, int64_t rows4, int64_t slabs4, unsigned vs) {
        cols = (cols4 + 1) / 2;
        rows = (rows4 + 1) / 2;
        slabs = (slabs4 + 1) / 2;
        valueSize = vs;
        const uint64_t n = uint64_t(cols) * uint64_t(rows) * uint64_t(slabs);
        solid.assign(size_t((n + 63) / 64), 0);
        values.assign(size_t(n * vs), 0);
        count = 0;
    }
    uint64_t index(int64_t col, int64_t row, int64_t slab) const { return (uint64_t(slab) * uint64_t(rows) + uint64_t(row)) * uint64_t(cols) + uint64_t(col); }
    // The block holding the brick at (x, y, z) (voxels) is solid.
    bool covers(int64_t x, int64_t y, int64_t z) const {
        if (count == 0) return false;
        const uint64_t i = index(x >> kSolidBlockLog2, y >> kSolidBlockLog2, z >> kSolidBlockLog2);
        return (solid[size_t(i / 64)] >> (i % 64)) & 1u;
    }
    const uint8_t* valueOf(int64_t col, int64_t row, int64_t slab) const { return values.data() + index(col, row, slab) * valueSize; }
    void set(int64_t col, int64_t row, int64_t slab, const uint8_t* value) {
        const uint64_t i = index(col, row, slab);
        solid[size_t(i / 64)] |= uint64_t(1) << (i % 64);
        std::memcpy(values.data() + i * valueSize, value, valueSize);
        ++count;
    }
};

// One 4-slice slab's bricks, as the import cuts them: whether each is full
// (mask all ones) with 64 equal values, and that value.
template <typename V>
struct SlabUniformity {
    std::vector<uint8_t> uniform;  // cols4 * rows4
    std::vector<V> value;
    void reset(int64_t cols4, int64_t rows4) {
        uniform.assign(size_t(cols4 * rows4), 0);
        value.assign(size_t(cols4 * rows4), V{});
    }
    // The brick (col, row) cut with `mask` whose 64 values end `kept`.
    void note(int64_t cols4, int64_t col, int64_t row, uint64_t mask, const std::vector<V>& kept) {
        if (mask != ~uint64_t(0)) return;
        const V* v = kept.data() + kept.size() - 64;
        for (int i = 1; i < 64; ++i)
            if (std::memcmp(&v[i], &v[0], sizeof(V)) != 0) return;
        uniform[size_t(row * cols4 + col)] = 1;
        value[size_t(row * cols4 + col)] = v[0];
    }
};

// The solid blocks of slab pair (lower: slab 2k, upper: 2k+1): each block
// whose 8 bricks are uniform with the same value.
template <typename V>
void markSolidBlocks(const SlabUniformity<V>& lower, const SlabUniformity<V>& upper, int64_t cols4, int64_t rows4, int64_t slab8, SolidBlocks& blocks) {
    for (int64_t r = 0; 2 * r + 1 < rows4; ++r)
        for (int64_t c = 0; 2 * c + 1 < cols4; ++c) {
            const size_t first = size_t(2 * r * cols4 + 2 * c);
            bool solid = true;
            for (int k = 0; k < 8 && solid; ++k) {
                const SlabUniformity<V>& s = (k & 4) ? upper : lower;
                const size_t i = size_t((2 * r + ((k >> 1) & 1)) * cols4 + 2 * c + (k & 1));
                solid = s.uniform[i] && std::memcmp(&s.value[i], &lower.value[first], sizeof(V)) == 0;
            }
            if (solid) blocks.set(c, r, slab8, reinterpret_cast<const uint8_t*>(&lower.value[first]));
        }
}

// The tile of block (col, row, slab).
inline Tile solidBlockTile(int64_t col, int64_t row, int64_t slab) {
    return {int32_t(col << kSolidBlockLog2), int32_t(row << kSolidBlockLog2), int32_t(slab << kSolidBlockLog2), uint8_t(kSolidBlockLog2)};
}

} // namespace vdbdag::bridge::detail
