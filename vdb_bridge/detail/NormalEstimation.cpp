// See NormalEstimation.h. Bricks are processed in parallel (one accessor per
// task); each brick's output position is the prefix sum of the popcounts
// before it, so the result does not depend on the thread count.
#include "vdb_bridge/detail/NormalEstimation.h"

#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>

#include <tbb/parallel_for.h>

namespace vdbdag::bridge::detail {
namespace {

using Vec = NormalVector;

void store(std::vector<uint8_t>& out, size_t index, const Vec& v) { std::memcpy(&out[index * sizeof(Vec)], v.data(), sizeof(Vec)); }

// Calls eval(accessor, coord) -> (vector, oneSided) for every active voxel
// and tile of `topology`, in input order.
template <typename GridT, typename Eval>
GridRecord::Normals evaluate(const GridT& grid, const GridTopology& topology, Eval eval) {
    GridRecord::Normals normals;
    std::vector<uint64_t> first(topology.bricks.size() + 1, 0);
    for (size_t i = 0; i < topology.bricks.size(); ++i) first[i + 1] = first[i] + uint64_t(std::popcount(topology.bricks[i].mask));
    normals.vectors.bricks.resize(first.back() * sizeof(Vec));
    normals.vectors.tiles.resize(topology.tiles.size() * sizeof(Vec));
    std::atomic<uint64_t> oneSided{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, topology.bricks.size(), 256), [&](const auto& range) {
        auto acc = grid.getConstAccessor();
        uint64_t local = 0;
        for (size_t i = range.begin(); i != range.end(); ++i) {
            const Brick& b = topology.bricks[i];
            uint64_t out = first[i];
            for (uint64_t bits = b.mask; bits; bits &= bits - 1, ++out) {
                const int bit = std::countr_zero(bits);
                const openvdb::Coord c(b.x + (bit & 3), b.y + ((bit >> 2) & 3), b.z + (bit >> 4));
                bool edge = false;
                store(normals.vectors.bricks, out, eval(acc, c, edge));
                local += edge ? 1 : 0;
            }
        }
        oneSided += local;
    });
    auto acc = grid.getConstAccessor();
    for (size_t t = 0; t < topology.tiles.size(); ++t) {
        const Tile& tile = topology.tiles[t];
        const int32_t half = int32_t(1) << (tile.log2Size - 1);
        bool edge = false;
        store(normals.vectors.tiles, t, eval(acc, openvdb::Coord(tile.x + half, tile.y + half, tile.z + half), edge));
        oneSided += edge ? 1 : 0;
    }
    normals.oneSided = oneSided.load();
    return normals;
}

template <typename GridT>
GridRecord::Normals gradient(const GridT& grid, const GridTopology& topology) {
    const openvdb::math::MapBase::ConstPtr map = grid.transform().baseMap();
    return evaluate(grid, topology, [&](auto& acc, const openvdb::Coord& c, bool& edge) {
        return gradientNormalAt<typename GridT::ValueType>([&](const openvdb::Coord& at, auto& value) { return acc.probeValue(at, value); }, *map, c, edge);
    });
}

template <typename GridT>
GridRecord::Normals fromVectors(const GridT& grid, const GridTopology& topology) {
    GridRecord::Normals n = evaluate(grid, topology, [](auto& acc, const openvdb::Coord& c, bool&) { return vectorNormal(acc.getValue(c)); });
    n.fromNormalGrid = true;
    return n;
}

} // namespace

GridRecord::Normals gradientNormals(const openvdb::FloatGrid& grid, const GridTopology& topology) { return gradient(grid, topology); }
GridRecord::Normals gradientNormals(const openvdb::DoubleGrid& grid, const GridTopology& topology) { return gradient(grid, topology); }
GridRecord::Normals gridNormals(const openvdb::Vec3SGrid& grid, const GridTopology& topology) { return fromVectors(grid, topology); }
GridRecord::Normals gridNormals(const openvdb::Vec3DGrid& grid, const GridTopology& topology) { return fromVectors(grid, topology); }
GridRecord::Normals gridNormals(const openvdb::Vec3IGrid& grid, const GridTopology& topology) { return fromVectors(grid, topology); }

} // namespace vdbdag::bridge::detail
