// Bottom-up SVDAG / SSVDAG construction (SSVDAG paper §4.1).
//
// Level by level, from the 4^3 bricks up to the root:
//  1. the node instances of the level, sorted in Morton order so that the 8
//     children of every parent are contiguous, are grouped into parents;
//     active tiles of the parent level are merged in as "solid" nodes (no
//     children, one attribute: a tile is never expanded);
//  2. every parent is put in canonical form: over the 8 reflections m, the
//     lexicographically smallest key, where the key of reflection m lists the
//     children as (index+1, tag) with child slot j taken from slot j^m and its
//     tag XORed with m, then reduced modulo the child's invariance group
//     (canonicalTag). The invariance group of the node is the set of m whose
//     key equals the identity's key. Unlike the paper's reference code, which
//     tracks one invariance bit per axis, this uses the full subgroup of Z2^3,
//     so a node invariant under a combined flip (e.g. XY) still matches its
//     mirror images;
//  3. canonical keys are hash-consed (LevelBuilder), giving the unique nodes.
// Canonicalisation runs in parallel; hash-consing is sequential in Morton
// order, so node indices (and the output file) do not depend on threads.
#include "src/dag/DagBuilder.h"

#include <algorithm>
#include <limits>
#include <string>

#include "src/dag/BuildParallel.h"
#include "src/dag/LevelBuilder.h"
#include "src/util/Error.h"

namespace vdbdag::dag {
namespace {

int64_t floorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

struct MortonInstanceLess {
    bool operator()(const Instance& a, const Instance& b) const { return mortonLess(a.cell, b.cell); }
};

void checkAlignment(const GridTopology& topo) {
    for (const Brick& b : topo.bricks)
        if ((b.x & 3) || (b.y & 3) || (b.z & 3)) throw Error("internal error: brick corner not a multiple of 4");
    for (const Tile& t : topo.tiles) {
        if (t.log2Size < 3 || t.log2Size > 31) throw Error("tile size 2^" + std::to_string(t.log2Size) + " out of range (8 to 2^31)");
        const int64_t size = int64_t(1) << t.log2Size;
        if ((t.x % size) || (t.y % size) || (t.z % size)) throw Error("internal error: tile not aligned to its size");
    }
}

CellCoord cellOf(const std::array<int64_t, 3>& origin, int64_t x, int64_t y, int64_t z, unsigned s) {
    return {uint32_t(uint64_t(x - origin[0]) >> s), uint32_t(uint64_t(y - origin[1]) >> s), uint32_t(uint64_t(z - origin[2]) >> s)};
}

} // namespace

RootPlacement placeRoot(const ActiveBounds& box, int64_t alignment, const BuildOptions& options) {
    RootPlacement placement{{0, 0, 0}, 3};
    unsigned log2 = 3;
    for (int a = 0; a < 3; ++a) {
        placement.origin[a] = options.origin ? (*options.origin)[a] : floorDiv(box.min[a], alignment) * alignment;
        if (placement.origin[a] % alignment != 0 || placement.origin[a] > box.min[a] || box.min[a] - placement.origin[a] > (int64_t(1) << 33))
            throw Error("root origin must be a multiple of " + std::to_string(alignment) + " at or below the active minimum");
        const uint64_t extent = uint64_t(box.max[a] - placement.origin[a]) + 1;
        while ((uint64_t(1) << log2) < extent) ++log2;
    }
    placement.log2Size = log2;
    if (options.log2Size) {
        if (*options.log2Size < log2 || *options.log2Size > 40 || (int64_t(1) << *options.log2Size) < alignment)
            throw Error("internal error: root size 2^" + std::to_string(*options.log2Size) + " does not cover the active box");
        placement.log2Size = *options.log2Size;
    }
    return placement;
}

ActiveBounds activeBounds(const GridTopology& topology) {
    ActiveBounds box;
    box.min.fill(std::numeric_limits<int64_t>::max());
    box.max.fill(std::numeric_limits<int64_t>::min());
    auto extend = [&](int64_t x, int64_t y, int64_t z, int64_t size) {
        const int64_t c[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) { box.min[a] = std::min(box.min[a], c[a]); box.max[a] = std::max(box.max[a], c[a] + size - 1); }
    };
    for (const Brick& b : topology.bricks) extend(b.x, b.y, b.z, 4);
    for (const Tile& t : topology.tiles) extend(t.x, t.y, t.z, int64_t(1) << t.log2Size);
    return box;
}

int64_t placementAlignment(const GridTopology& topology) {
    unsigned largest = 2;
    for (const Tile& t : topology.tiles) largest = std::max<unsigned>(largest, t.log2Size);
    return int64_t(1) << largest;
}

ReducedDag buildDag(const GridTopology& topology, const BuildOptions& options) {
    ReducedDag dag;
    if (topology.empty()) return dag;
    checkAlignment(topology);
    const RootPlacement placement = placeRoot(activeBounds(topology), placementAlignment(topology), options);
    dag.origin = placement.origin;
    dag.log2Size = placement.log2Size;
    LevelBuilder levels(dag, options.symmetry);

    const auto& in = topology.bricks;
    std::vector<Instance> level(in.size());
    detail::forEachRange(in.size(), 4096, [&](size_t begin, size_t end) {
        for (size_t i = begin; i != end; ++i) level[i] = {cellOf(dag.origin, in[i].x, in[i].y, in[i].z, 2), uint32_t(i)};  // ref: input position, for now
    });
    detail::sortRange(level.begin(), level.end(), MortonInstanceLess{});
    std::vector<uint64_t> masks(level.size());
    for (size_t i = 0; i < level.size(); ++i) {
        if (i > 0 && level[i].cell == level[i - 1].cell) throw Error("internal error: two bricks at the same position");
        masks[i] = in[level[i].ref].mask;
    }
    const std::vector<ChildRef> refs = levels.addBricks(masks);
    for (size_t i = 0; i < level.size(); ++i) level[i].ref = refs[i];
    dag.svoNodeCount[0] = level.size();

    for (unsigned s = 3; s <= dag.log2Size; ++s) {
        std::vector<CellCoord> tiles;
        for (const Tile& t : topology.tiles)
            if (t.log2Size == s) tiles.push_back(cellOf(dag.origin, t.x, t.y, t.z, s));
        level = levels.raise(level, std::move(tiles), s);
    }
    if (level.size() != 1 || !(level[0].cell == CellCoord{0, 0, 0})) throw Error("internal error: DAG build did not converge to one root");
    dag.root = level[0].ref;
    countReferences(dag);
    return dag;
}

} // namespace vdbdag::dag
