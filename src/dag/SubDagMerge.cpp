// See SubDagMerge.h. A sub-DAG's node of level s lists its children by
// local index; its instance in the whole DAG lists them by global index,
// with each child's reflection composed with the reflection that maps the
// global representative onto the local one (reflections commute). That raw
// node is canonicalised and hash-consed like any node of the in-core build.
#include "src/dag/SubDagMerge.h"

#include <algorithm>
#include <string>

#include "src/util/Error.h"

namespace vdbdag::dag {
namespace {

ReducedDag emptyWhole(const RootPlacement& whole) {
    ReducedDag dag;
    dag.origin = whole.origin;
    dag.log2Size = whole.log2Size;
    return dag;
}

// `local` is a reference into the sub-DAG; `toGlobal` maps its index.
ChildRef compose(ChildRef local, const std::vector<ChildRef>& toGlobal) {
    const ChildRef g = toGlobal[childIndex(local)];
    return makeChildRef(childIndex(g), childReflection(local) ^ childReflection(g));
}

} // namespace

SubDagMerger::SubDagMerger(const RootPlacement& whole, unsigned cubeLog2, bool symmetry)
    : dag_(emptyWhole(whole)), cubeLog2_(cubeLog2), levels_(dag_, symmetry) {
    if (cubeLog2 < 3 || cubeLog2 >= whole.log2Size) throw Error("internal error: cube size 2^" + std::to_string(cubeLog2) + " does not split the grid");
}

void SubDagMerger::add(CellCoord cube, const ReducedDag& sub) {
    if (sub.log2Size != cubeLog2_ || sub.root == 0) throw Error("internal error: a sub-DAG is empty or not of the cube's size");
    if (!cubes_.empty() && !mortonLess(cubes_.back().cell, cube)) throw Error("internal error: sub-DAGs out of Morton order");
    std::vector<ChildRef> below(sub.bricks.size());
    for (size_t i = 0; i < sub.bricks.size(); ++i) below[i] = levels_.addBrick(sub.bricks[i]);
    for (unsigned s = 3; s <= cubeLog2_; ++s) {
        const auto& nodes = sub.inner[s - 3].nodes;
        std::vector<ChildRef> here(nodes.size());
        for (size_t n = 0; n < nodes.size(); ++n) {
            InnerNode raw{};
            for (unsigned j = 0; j < 8; ++j)
                if (nodes[n][j]) raw[j] = compose(nodes[n][j], below);
            here[n] = levels_.addInner(s, raw);
        }
        below = std::move(here);
    }
    for (unsigned s = 2; s <= cubeLog2_; ++s) dag_.svoNodeCount[s - 2] += sub.svoNodeCount[s - 2];
    cubes_.push_back({cube, compose(sub.root, below)});
}

ReducedDag SubDagMerger::finish(const std::vector<std::pair<CellCoord, unsigned>>& largeTiles) {
    std::vector<Instance> level = std::move(cubes_);
    for (unsigned s = cubeLog2_ + 1; s <= dag_.log2Size; ++s) {
        std::vector<CellCoord> tiles;
        for (const auto& [cell, log2] : largeTiles) {
            if (log2 <= cubeLog2_) throw Error("internal error: a tile no larger than a cube passed as a large tile");
            if (log2 == s) tiles.push_back(cell);
        }
        level = levels_.raise(level, std::move(tiles), s);
    }
    if (level.size() != 1 || !(level[0].cell == CellCoord{0, 0, 0})) throw Error("internal error: DAG merge did not converge to one root");
    dag_.root = level[0].ref;
    countReferences(dag_);
    return std::move(dag_);
}

std::vector<TopologyCube> splitIntoCubes(const GridTopology& topology, const RootPlacement& placement, unsigned cubeLog2,
                                         std::vector<std::pair<CellCoord, unsigned>>& largeTiles) {
    const auto& o = placement.origin;
    auto cellOf = [&](int64_t x, int64_t y, int64_t z, unsigned s) {
        return CellCoord{uint32_t(uint64_t(x - o[0]) >> s), uint32_t(uint64_t(y - o[1]) >> s), uint32_t(uint64_t(z - o[2]) >> s)};
    };
    struct Item { CellCoord cube; bool tile; size_t index; };
    std::vector<Item> items;
    items.reserve(topology.bricks.size() + topology.tiles.size());
    for (size_t i = 0; i < topology.bricks.size(); ++i) {
        const Brick& b = topology.bricks[i];
        items.push_back({cellOf(b.x, b.y, b.z, cubeLog2), false, i});
    }
    for (size_t i = 0; i < topology.tiles.size(); ++i) {
        const Tile& t = topology.tiles[i];
        if (t.log2Size > cubeLog2) largeTiles.push_back({cellOf(t.x, t.y, t.z, t.log2Size), t.log2Size});
        else items.push_back({cellOf(t.x, t.y, t.z, cubeLog2), true, i});
    }
    std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return mortonLess(a.cube, b.cube); });
    std::vector<TopologyCube> cubes;
    for (const Item& item : items) {
        if (cubes.empty() || !(cubes.back().cell == item.cube)) cubes.push_back({item.cube, {}});
        if (item.tile) cubes.back().topology.tiles.push_back(topology.tiles[item.index]);
        else cubes.back().topology.bricks.push_back(topology.bricks[item.index]);
    }
    return cubes;
}

ReducedDag buildDagByCubes(const GridTopology& topology, const BuildOptions& options, unsigned cubeLog2) {
    if (topology.empty()) return {};
    const RootPlacement whole = placeRoot(activeBounds(topology), placementAlignment(topology), options);
    if (cubeLog2 >= whole.log2Size) return buildDag(topology, options);
    std::vector<std::pair<CellCoord, unsigned>> largeTiles;
    const std::vector<TopologyCube> cubes = splitIntoCubes(topology, whole, cubeLog2, largeTiles);
    SubDagMerger merger(whole, cubeLog2, options.symmetry);
    for (const TopologyCube& cube : cubes) {
        BuildOptions local = options;
        local.origin = std::array<int64_t, 3>{whole.origin[0] + (int64_t(cube.cell.x) << cubeLog2), whole.origin[1] + (int64_t(cube.cell.y) << cubeLog2),
                                              whole.origin[2] + (int64_t(cube.cell.z) << cubeLog2)};
        local.log2Size = cubeLog2;
        merger.add(cube.cell, buildDag(cube.topology, local));
    }
    return merger.finish(largeTiles);
}

} // namespace vdbdag::dag
