// Private: an OpenVDB leaf (8^3) as the 4^3 bricks of vdbdag's two layers
// (GridRecord): the active voxels, and the inactive voxels whose value is
// not bitwise the background. Values are raw bytes (bool as one byte), so
// they round-trip bit-exactly. Shared by the whole-file import (VdbImport)
// and the cube-by-cube reader (VdbCubes).
#pragma once
#include <bit>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

#include <openvdb/openvdb.h>

#include "src/volume/CubeSource.h"
#include "src/volume/LeafMask.h"

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

// The inverse of appendValue: the value whose raw bytes start at `p`.
template <typename T>
T valueFromBytes(const uint8_t* p) {
    if constexpr (std::is_same_v<T, bool>) {
        return *p != 0;
    } else {
        T v;
        std::memcpy(&v, p, sizeof(T));
        return v;
    }
}

template <typename T>
bool sameBits(const T& a, const T& b) {
    if constexpr (std::is_same_v<T, bool>) return a == b;
    else return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Whether every value of `values` (each `valueSize` bytes) has the same bits.
inline bool allSameValue(const std::vector<uint8_t>& values, unsigned valueSize) {
    for (size_t at = valueSize; valueSize && at + valueSize <= values.size(); at += valueSize)
        if (std::memcmp(values.data(), values.data() + at, valueSize) != 0) return false;
    return true;
}

// Brick b (0..7) of a leaf is the 4^3 block at ((b&1)*4, (b>>1&1)*4, (b>>2&1)*4).
inline openvdb::Coord brickCorner(const openvdb::Coord& leafOrigin, unsigned b) {
    return leafOrigin.offsetBy(int(b & 1u) * 4, int((b >> 1) & 1u) * 4, int((b >> 2) & 1u) * 4);
}

// Brick b's voxels among the leaf mask's (src/volume/LeafMask.h).
using vdbdag::brickOfLeafMask;

// Leaf voxel index of brick b's bit `bit`.
inline openvdb::Index leafIndexOf(unsigned b, unsigned bit) {
    const unsigned x = (b & 1u) * 4 + (bit & 3u), y = ((b >> 1) & 1u) * 4 + ((bit >> 2) & 3u), z = ((b >> 2) & 1u) * 4 + (bit >> 4);
    return openvdb::Index((x << 6) | (y << 3) | z);
}

// The mask of brick b of `leaf` in `layer`; with `values`, appends the
// values of its set bits in increasing bit order. Layer::Inactive reads
// the leaf's values (loading a delayed buffer); Layer::Active without
// values reads the value mask only.
template <typename LeafT, bool hasValues>
uint64_t leafBrick(const LeafT& leaf, unsigned b, Layer layer, const typename LeafT::ValueType& background, std::vector<uint8_t>* values) {
    using ValueT = typename LeafT::ValueType;
    if constexpr (!hasValues) {
        if (layer == Layer::Inactive) return 0;
    }
    uint64_t words[8];
    for (unsigned w = 0; w < 8; ++w) words[w] = leaf.getValueMask().template getWord<uint64_t>(w);
    const uint64_t active = brickOfLeafMask(words, b);
    if (layer == Layer::Active) {
        if constexpr (hasValues) {
            if (values && active) {
                if constexpr (std::is_same_v<ValueT, bool>) {
                    for (uint64_t bits = active; bits; bits &= bits - 1) appendValue(*values, leaf.getValue(leafIndexOf(b, unsigned(std::countr_zero(bits)))));
                } else {
                    const ValueT* data = leaf.buffer().data();
                    const size_t at = values->size();
                    values->resize(at + size_t(std::popcount(active)) * sizeof(ValueT));
                    uint8_t* out = values->data() + at;
                    for (uint64_t bits = active; bits; bits &= bits - 1, out += sizeof(ValueT))
                        std::memcpy(out, &data[leafIndexOf(b, unsigned(std::countr_zero(bits)))], sizeof(ValueT));
                }
            }
        }
        return active;
    }
    uint64_t mask = 0;
    if constexpr (hasValues) {
        auto visit = [&](auto valueAt) {
            for (uint64_t bits = ~active; bits; bits &= bits - 1) {
                const unsigned bit = unsigned(std::countr_zero(bits));
                const ValueT value = valueAt(leafIndexOf(b, bit));
                if (sameBits(value, background)) continue;
                mask |= uint64_t(1) << bit;
                if (values) appendValue(*values, value);
            }
        };
        if constexpr (std::is_same_v<ValueT, bool>) {
            visit([&](openvdb::Index n) { return leaf.getValue(n); });
        } else {
            const ValueT* data = leaf.buffer().data();
            visit([&](openvdb::Index n) { return data[n]; });
        }
    }
    return mask;
}

} // namespace vdbdag::bridge::detail
