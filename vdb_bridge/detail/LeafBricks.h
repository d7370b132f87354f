// Private: an OpenVDB leaf (8^3) as the 4^3 bricks of vdbdag's two layers
// (GridRecord): the active voxels, and the inactive voxels whose value is
// not bitwise the background. Values are raw bytes (bool as one byte), so
// they round-trip bit-exactly. Shared by the whole-file import (VdbImport)
// and the cube-by-cube reader (VdbCubes).
#pragma once
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include <openvdb/openvdb.h>

#include "src/volume/CubeSource.h"

namespace vdbdag::bridge::detail {

template <typename T>
void appendValue(std::vector<uint8_t>& out, const T& value) {
    if constexpr (std::is_same_v<T, bool>) {
        out.push_back(value ? 1 : 0);
    } else {
        const auto* p = reinterpret_cast<const uint8_t*>(&value);
        out.insert(out.end(), p, p + sizeof(T));
    }
}

template <typename T>
bool sameBits(const T& a, const T& b) {
    if constexpr (std::is_same_v<T, bool>) return a == b;
    else return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Brick b (0..7) of a leaf is the 4^3 block at ((b&1)*4, (b>>1&1)*4, (b>>2&1)*4).
inline openvdb::Coord brickCorner(const openvdb::Coord& leafOrigin, unsigned b) {
    return leafOrigin.offsetBy(int(b & 1u) * 4, int((b >> 1) & 1u) * 4, int((b >> 2) & 1u) * 4);
}

// The mask of brick b of `leaf` in `layer`; with `values`, appends the
// values of its set bits in increasing bit order. Layer::Inactive reads
// the leaf's values (loading a delayed buffer); Layer::Active without
// values reads the value mask only.
template <typename LeafT, bool hasValues>
uint64_t leafBrick(const LeafT& leaf, unsigned b, Layer layer, const typename LeafT::ValueType& background, std::vector<uint8_t>* values) {
    if constexpr (!hasValues) {
        if (layer == Layer::Inactive) return 0;
    }
    const int bx = int(b & 1u) * 4, by = int((b >> 1) & 1u) * 4, bz = int((b >> 2) & 1u) * 4;
    uint64_t mask = 0;
    for (int bit = 0; bit < 64; ++bit) {
        const int x = bx + (bit & 3), y = by + ((bit >> 2) & 3), z = bz + (bit >> 4);
        const openvdb::Index n = openvdb::Index((x << 6) | (y << 3) | z);
        const bool on = leaf.isValueOn(n);
        if (layer == Layer::Active) {
            if (!on) continue;
            mask |= uint64_t(1) << bit;
            if constexpr (hasValues)
                if (values) appendValue(*values, leaf.getValue(n));
        } else if constexpr (hasValues) {
            if (on || sameBits(leaf.getValue(n), background)) continue;
            mask |= uint64_t(1) << bit;
            if (values) appendValue(*values, leaf.getValue(n));
        }
    }
    return mask;
}

} // namespace vdbdag::bridge::detail
