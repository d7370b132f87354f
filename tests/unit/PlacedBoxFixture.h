// Test fixture for the placed value coders (BrickValueCoder, LabelCoder): a
// dense 32^3 box of full 4^3 bricks in Morton order, as a DAG's attribute
// order visits a full box, each brick with its place and a mirror drawn
// from `rng` (0 without mirrors); `value(X, Y, Z)` gives the sample at a
// spatial voxel, stored at the voxel's stored bit (dag_access.h
// dagStoredBit), so a coder must undo the mirror to see the field. Every
// brick m with m % tileEvery == tileAt is a tile holding `tileValue` (4^3
// wide, which no DAG stores: no neighbour to label model generation 3;
// placedBlockBox below has real 8^3 tiles).
#pragma once
#include <bit>
#include <cstdint>
#include <random>
#include <vector>

#include "src/coding/BrickValueCoder.h"
#include "src/dag/Reflection.h"

namespace vdbdag::coding::testing {

struct PlacedChannel {
    std::vector<uint64_t> layout;
    std::vector<BrickPlace> places;
    std::vector<int32_t> entries;
};

// Cell m of 8 x 8 x 8 in Morton order (x's bit lowest at each level).
inline void mortonCell(uint32_t m, int& x, int& y, int& z) {
    x = y = z = 0;
    for (int k = 0; k < 3; ++k) x |= int(m >> (3 * k) & 1) << k, y |= int(m >> (3 * k + 1) & 1) << k, z |= int(m >> (3 * k + 2) & 1) << k;
}

template <typename Value>
PlacedChannel placedBox(std::mt19937& rng, bool mirrors, Value&& value, uint32_t tileEvery = 0, uint32_t tileAt = 0, int32_t tileValue = 0) {
    PlacedChannel c;
    for (uint32_t m = 0; m < 512; ++m) {  // 8^3 bricks, Morton order
        int bx, by, bz;
        mortonCell(m, bx, by, bz);
        const uint32_t mirror = mirrors ? rng() % 8 : 0;
        const bool tile = tileEvery && m % tileEvery == tileAt;
        c.layout.push_back(tile ? 0 : ~uint64_t(0));
        c.places.push_back(tile ? tilePlace(4 * bx, 4 * by, 4 * bz, 2) : BrickPlace{4 * bx, 4 * by, 4 * bz, mirror});
        if (tile) {
            c.entries.push_back(tileValue);
            continue;
        }
        std::vector<int32_t> brick(64);
        for (int z = 0; z < 4; ++z)
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 4; ++x)
                    brick[access::dagStoredBit(unsigned(x), unsigned(y), unsigned(z), mirror)] = value(4 * bx + x, 4 * by + y, 4 * bz + z);
        c.entries.insert(c.entries.end(), brick.begin(), brick.end());
    }
    return c;
}

// The same 32^3 box as a scan's import lays it out: each 8^3 block whose
// 512 values are one is a tile (tilePlace, 8 wide) holding it, the others
// their 8 full bricks with mirrors drawn from `rng`; blocks and bricks in
// Morton order, as a DAG's attribute order visits them. `value` must give
// the same sample each time it is asked.
template <typename Value>
PlacedChannel placedBlockBox(std::mt19937& rng, Value&& value) {
    PlacedChannel c;
    for (uint32_t b = 0; b < 64; ++b) {  // 4^3 blocks of 8^3
        int bx, by, bz;
        mortonCell(b, bx, by, bz);
        const int x0 = 8 * bx, y0 = 8 * by, z0 = 8 * bz;
        bool uniform = true;
        for (int k = 1; k < 512 && uniform; ++k) uniform = value(x0 + (k & 7), y0 + (k >> 3 & 7), z0 + (k >> 6)) == value(x0, y0, z0);
        if (uniform) {
            c.layout.push_back(0);
            c.places.push_back(tilePlace(x0, y0, z0, 3));
            c.entries.push_back(value(x0, y0, z0));
            continue;
        }
        for (uint32_t m = 0; m < 8; ++m) {
            int x, y, z;
            mortonCell(m, x, y, z);
            const int X0 = x0 + 4 * x, Y0 = y0 + 4 * y, Z0 = z0 + 4 * z;
            const uint32_t mirror = rng() % 8;
            c.layout.push_back(~uint64_t(0));
            c.places.push_back({X0, Y0, Z0, mirror});
            std::vector<int32_t> brick(64);
            for (int k = 0; k < 64; ++k)
                brick[access::dagStoredBit(unsigned(k & 3), unsigned(k >> 2 & 3), unsigned(k >> 4), mirror)] = value(X0 + (k & 3), Y0 + (k >> 2 & 3), Z0 + (k >> 4));
            c.entries.insert(c.entries.end(), brick.begin(), brick.end());
        }
    }
    return c;
}

// The same instances in the reverse order (each brick's entries kept), as
// a DAG visits a box under a mirror on every axis: from the far corner.
inline PlacedChannel reversedBricks(const PlacedChannel& c) {
    PlacedChannel out;
    std::vector<size_t> first;
    size_t e = 0;
    for (const uint64_t mask : c.layout) first.push_back(e), e += mask ? size_t(std::popcount(mask)) : 1;
    for (size_t b = c.layout.size(); b-- > 0;) {
        out.layout.push_back(c.layout[b]);
        out.places.push_back(c.places[b]);
        const size_t n = c.layout[b] ? size_t(std::popcount(c.layout[b])) : 1;
        out.entries.insert(out.entries.end(), c.entries.begin() + long(first[b]), c.entries.begin() + long(first[b] + n));
    }
    return out;
}

} // namespace vdbdag::coding::testing
