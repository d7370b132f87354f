// Private (VdbStreamCompare.cpp): one cube of a layer as an .ssvdag scene
// decodes it (pipeline/LayerScatter.h), in a dense buffer: which voxels it
// holds and their value bytes. A solid cube (a tile) holds one value.
#pragma once
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include <openvdb/openvdb.h>

#include "src/encoding/CompactDag.h"
#include "src/util/Error.h"

namespace vdbdag::bridge::detail {

// Cubes of up to 2^log2 voxels a side (the layer's cut), `valueSize` bytes a value.
class DecodedCube {
public:
    DecodedCube(unsigned valueSize, unsigned log2) : vs_(valueSize) {
        const size_t voxels = size_t(1) << (3 * log2);
        bits_.resize(std::max<size_t>(1, voxels / 64));
        values_.resize(voxels * valueSize);
    }

    void begin(const encoding::SubtreeInstance& s, const std::string& what) {
        const int64_t limit = int64_t(1) << 31;
        if (s.log2Size > 21 || s.x < -limit || s.y < -limit || s.z < -limit || s.x + (int64_t(1) << s.log2Size) > limit ||
            s.y + (int64_t(1) << s.log2Size) > limit || s.z + (int64_t(1) << s.log2Size) > limit)
            throw Error(what + ": a cube outside OpenVDB's index space");
        x_ = s.x, y_ = s.y, z_ = s.z;
        log2_ = s.log2Size;
        uniform_ = s.solid;
        voxels_ = 0;
        if (!uniform_) {
            if (size_t(1) << (3 * log2_) > bits_.size() * 64) throw Error(what + ": a cube larger than its layer's cut");
            std::fill(bits_.begin(), bits_.begin() + std::max<size_t>(1, (size_t(1) << (3 * log2_)) / 64), 0);
        }
    }

    void brick(int64_t x, int64_t y, int64_t z, uint64_t mask, const uint8_t* values) {
        for (uint64_t bits = mask; bits; bits &= bits - 1) {
            const unsigned i = unsigned(std::countr_zero(bits));
            set(index(x + (i & 3), y + ((i >> 2) & 3), z + (i >> 4)), values);
            if (values) values += vs_;
        }
    }

    void solid(int64_t x, int64_t y, int64_t z, unsigned log2, const uint8_t* value) {
        if (uniform_) {
            voxels_ += uint64_t(1) << (3 * log2);
            if (vs_) std::memcpy(values_.data(), value, vs_);
            return;
        }
        const int64_t n = int64_t(1) << log2;
        for (int64_t k = 0; k < n; ++k)
            for (int64_t j = 0; j < n; ++j)
                for (int64_t i = 0; i < n; ++i) set(index(x + i, y + j, z + k), value);
    }

    openvdb::CoordBBox box() const {
        const openvdb::Coord lo{int32_t(x_), int32_t(y_), int32_t(z_)};
        return {lo, lo.offsetBy(int32_t((int64_t(1) << log2_) - 1))};
    }
    bool uniform() const { return uniform_; }
    uint64_t voxels() const { return voxels_; }
    size_t index(const openvdb::Coord& c) const { return index(c.x(), c.y(), c.z()); }
    bool has(size_t i) const { return uniform_ || ((bits_[i >> 6] >> (i & 63)) & 1u); }
    const uint8_t* value(size_t i) const { return values_.data() + (uniform_ ? 0 : i * vs_); }
    // The voxel slots of a cube that is not uniform, as words of bits.
    size_t words() const { return std::max<size_t>(1, (size_t(1) << (3 * log2_)) / 64); }
    uint64_t word(size_t w) const { return bits_[w]; }
    openvdb::Coord coordOf(size_t i) const {
        const size_t m = (size_t(1) << log2_) - 1;
        return {int32_t(x_ + int64_t(i & m)), int32_t(y_ + int64_t((i >> log2_) & m)), int32_t(z_ + int64_t(i >> (2 * log2_)))};
    }

private:
    size_t index(int64_t x, int64_t y, int64_t z) const {
        return size_t(((z - z_) << (2 * log2_)) | ((y - y_) << log2_) | (x - x_));
    }
    void set(size_t i, const uint8_t* value) {
        const uint64_t bit = uint64_t(1) << (i & 63);
        if (!(bits_[i >> 6] & bit)) ++voxels_;
        bits_[i >> 6] |= bit;
        if (vs_ && value) std::memcpy(values_.data() + i * vs_, value, vs_);
    }

    unsigned vs_;
    int64_t x_ = 0, y_ = 0, z_ = 0;
    unsigned log2_ = 0;
    bool uniform_ = false;
    uint64_t voxels_ = 0;
    std::vector<uint64_t> bits_;
    std::vector<uint8_t> values_;
};

} // namespace vdbdag::bridge::detail
