// See AttributeOrder.h. A brick instance's entries are its stored mask's set
// bits in increasing order; stored bit b is the spatial voxel reflect(m, b),
// whose value sits at that voxel's rank in the input brick.
#include "src/pipeline/AttributeOrder.h"

#include <bit>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "src/util/Error.h"

namespace vdbdag::pipeline {
namespace {

// reflectedBit[m][b]: the bit index of voxel b reflected by m.
struct ReflectedBits {
    uint8_t bit[8][64];
    constexpr ReflectedBits() : bit{} {
        for (unsigned m = 0; m < 8; ++m)
            for (unsigned b = 0; b < 64; ++b) {
                const unsigned x = b & 3u, y = (b >> 2) & 3u, z = b >> 4;
                const unsigned rx = (m & 1u) ? 3 - x : x, ry = (m & 2u) ? 3 - y : y, rz = (m & 4u) ? 3 - z : z;
                bit[m][b] = uint8_t(rx | (ry << 2) | (rz << 4));
            }
    }
};
constexpr ReflectedBits kReflected{};

struct CoordKey {
    int64_t x, y, z;
    bool operator==(const CoordKey&) const = default;
};
struct CoordHash {
    size_t operator()(const CoordKey& c) const {
        uint64_t h = uint64_t(c.x) * 0x9E3779B97F4A7C15ull ^ uint64_t(c.y) * 0xC2B2AE3D27D4EB4Full ^ uint64_t(c.z) * 0x165667B19E3779F9ull;
        return size_t(h ^ (h >> 29));
    }
};

inline unsigned rankBelow(uint64_t mask, unsigned bit) { return unsigned(std::popcount(mask & ((uint64_t(1) << bit) - 1))); }

} // namespace

namespace {

// Input position of every brick's first value and of every tile, and the
// copy of one instance's values into attribute order.
class InputValues {
public:
    InputValues(const GridTopology& topology, const LayerValues& values, unsigned valueSize) : values_(values), vs_(valueSize) {
        bricks_.reserve(topology.bricks.size());
        uint64_t next = 0;
        for (const Brick& b : topology.bricks) {
            bricks_.emplace(CoordKey{b.x, b.y, b.z}, std::make_pair(next, b.mask));
            next += uint64_t(std::popcount(b.mask));
        }
        if (values.bricks.size() != next * valueSize || values.tiles.size() != topology.tiles.size() * valueSize)
            throw Error("internal error: value count does not match the topology");
        for (size_t t = 0; t < topology.tiles.size(); ++t) tiles_.emplace(CoordKey{topology.tiles[t].x, topology.tiles[t].y, topology.tiles[t].z}, t);
    }

    void brick(const encoding::BrickInstance& b, uint8_t* out) const {
        const auto it = bricks_.find(CoordKey{b.x, b.y, b.z});
        if (it == bricks_.end()) throw Error("internal error: DAG brick missing from the input");
        const auto [first, inputMask] = it->second;
        uint64_t entry = b.firstEntry;
        for (uint64_t bits = b.storedMask; bits; bits &= bits - 1, ++entry) {
            const unsigned spatial = kReflected.bit[b.mirror][std::countr_zero(bits)];
            std::memcpy(out + entry * vs_, &values_.bricks[(first + rankBelow(inputMask, spatial)) * vs_], vs_);
        }
    }

    void solid(int64_t x, int64_t y, int64_t z, uint64_t entry, uint8_t* out) const {
        const auto it = tiles_.find(CoordKey{x, y, z});
        if (it == tiles_.end()) throw Error("internal error: DAG solid node missing from the input tiles");
        std::memcpy(out + entry * vs_, &values_.tiles[it->second * vs_], vs_);
    }

private:
    const LayerValues& values_;
    unsigned vs_;
    std::unordered_map<CoordKey, std::pair<uint64_t, uint64_t>, CoordHash> bricks_;  // -> (first value, mask)
    std::unordered_map<CoordKey, uint64_t, CoordHash> tiles_;
};

} // namespace

std::vector<uint8_t> gatherAttributes(const encoding::CompactDag& dag, const GridTopology& topology, const LayerValues& values,
                                      unsigned valueSize) {
    if (valueSize == 0) return {};
    const InputValues input(topology, values, valueSize);
    std::vector<uint8_t> out(encoding::decodedSize(dag).attributeEntries * valueSize);
    encoding::visitInAttributeOrder(
        dag, [&](const encoding::BrickInstance& b) { input.brick(b, out.data()); },
        [&](int64_t x, int64_t y, int64_t z, unsigned, uint64_t entry) { input.solid(x, y, z, entry, out.data()); });
    return out;
}

void gatherSubtree(const encoding::CompactDag& dag, const encoding::SubtreeInstance& subtree, const GridTopology& topology,
                   const LayerValues& values, unsigned valueSize, uint8_t* buffer, uint64_t bufferFirstEntry, std::vector<uint64_t>* layout,
                   std::vector<coding::BrickPlace>* places) {
    if (valueSize == 0) return;
    if (subtree.firstEntry < bufferFirstEntry) throw Error("internal error: a subtree's values start before the buffer");
    // Entry e goes to buffer + (e - bufferFirstEntry) * valueSize.
    encoding::SubtreeInstance shifted = subtree;
    shifted.firstEntry -= bufferFirstEntry;
    uint8_t* const attributes = buffer;
    const InputValues input(topology, values, valueSize);
    if (shifted.solid) {
        input.solid(shifted.x, shifted.y, shifted.z, shifted.firstEntry, attributes);
        if (layout) layout->push_back(0);
        if (places) places->push_back(coding::tilePlace(shifted.x, shifted.y, shifted.z, shifted.log2Size));
        return;
    }
    encoding::visitSubtreeInAttributeOrder(
        dag, shifted,
        [&](const encoding::BrickInstance& b) {
            input.brick(b, attributes);
            if (layout) layout->push_back(b.storedMask);
            if (places) places->push_back({int32_t(b.x), int32_t(b.y), int32_t(b.z), b.mirror});
        },
        [&](int64_t x, int64_t y, int64_t z, unsigned log2Size, uint64_t entry) {
            input.solid(x, y, z, entry, attributes);
            if (layout) layout->push_back(0);
            if (places) places->push_back(coding::tilePlace(x, y, z, log2Size));
        });
}

void scatterSubtree(const encoding::CompactDag& dag, const encoding::SubtreeInstance& subtree, const uint8_t* values, unsigned valueSize,
                    const SubtreeVoxels& visit) {
    const uint64_t base = subtree.firstEntry;
    if (subtree.solid) {
        visit.solid(subtree.x, subtree.y, subtree.z, subtree.log2Size, valueSize ? values : nullptr);
        return;
    }
    uint8_t brick[64 * 64];  // a brick's values in spatial order (at most 64 bytes each)
    if (valueSize > 64) throw Error("internal error: values of more than 64 bytes");
    encoding::visitSubtreeInAttributeOrder(
        dag, subtree,
        [&](const encoding::BrickInstance& b) {
            const uint64_t spatialMask = b.spatialMask();
            if (valueSize) {
                uint64_t entry = b.firstEntry - base;
                for (uint64_t bits = b.storedMask; bits; bits &= bits - 1, ++entry) {
                    const unsigned spatial = kReflected.bit[b.mirror][std::countr_zero(bits)];
                    std::memcpy(brick + rankBelow(spatialMask, spatial) * valueSize, values + entry * valueSize, valueSize);
                }
            }
            visit.brick(b.x, b.y, b.z, spatialMask, brick);
        },
        [&](int64_t x, int64_t y, int64_t z, unsigned log2Size, uint64_t entry) {
            const int64_t tileSize = int64_t(1) << log2Size;
            if (log2Size > 31 || (x & (tileSize - 1)) || (y & (tileSize - 1)) || (z & (tileSize - 1)))
                throw Error("solid node of 2^" + std::to_string(log2Size) + " voxels at (" + std::to_string(x) + "," + std::to_string(y) + "," +
                            std::to_string(z) + ") is not aligned to its size: the file is corrupted");
            visit.solid(x, y, z, log2Size, valueSize ? values + (entry - base) * valueSize : nullptr);
        });
}

void scatterAttributes(const encoding::CompactDag& dag, const std::vector<uint8_t>& attributes, unsigned valueSize,
                       GridTopology& topology, LayerValues& values) {
    topology = {};
    values = {};
    const encoding::DecodedSize size = encoding::decodedSize(dag);
    if (valueSize && attributes.size() != size.attributeEntries * valueSize)
        throw Error("value channel holds " + std::to_string(attributes.size() / std::max(1u, valueSize)) + " entries, the DAG needs " +
                    std::to_string(size.attributeEntries));
    topology.bricks.reserve(size.emittedBricks);
    auto toInt32 = [](int64_t v) {
        if (v < std::numeric_limits<int32_t>::min() || v > std::numeric_limits<int32_t>::max())
            throw Error("decoded coordinate " + std::to_string(v) + " is outside OpenVDB's int32 index range");
        return int32_t(v);
    };
    encoding::visitInAttributeOrder(
        dag,
        [&](const encoding::BrickInstance& b) {
            const uint64_t spatialMask = b.spatialMask();
            topology.bricks.push_back({toInt32(b.x), toInt32(b.y), toInt32(b.z), spatialMask});
            if (!valueSize) return;
            const size_t base = values.bricks.size();
            values.bricks.resize(base + size_t(std::popcount(spatialMask)) * valueSize);
            uint64_t entry = b.firstEntry;
            for (uint64_t bits = b.storedMask; bits; bits &= bits - 1, ++entry) {
                const unsigned spatial = kReflected.bit[b.mirror][std::countr_zero(bits)];
                std::memcpy(&values.bricks[base + rankBelow(spatialMask, spatial) * valueSize], &attributes[entry * valueSize], valueSize);
            }
        },
        [&](int64_t x, int64_t y, int64_t z, unsigned log2Size, uint64_t entry) {
            const int64_t tileSize = int64_t(1) << log2Size;
            if (log2Size > 31 || (x & (tileSize - 1)) || (y & (tileSize - 1)) || (z & (tileSize - 1)))
                throw Error("solid node of 2^" + std::to_string(log2Size) + " voxels at (" + std::to_string(x) + "," + std::to_string(y) + "," +
                            std::to_string(z) + ") is not aligned to its size: the file is corrupted");
            topology.tiles.push_back({toInt32(x), toInt32(y), toInt32(z), uint8_t(log2Size)});
            if (valueSize) values.tiles.insert(values.tiles.end(), attributes.begin() + long(entry * valueSize), attributes.begin() + long((entry + 1) * valueSize));
        });
}

} // namespace vdbdag::pipeline
