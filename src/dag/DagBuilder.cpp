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
//  3. canonical keys are hash-consed (NodeTable), giving the unique nodes.
// Canonicalisation runs in parallel; hash-consing is sequential in Morton
// order, so node indices (and the output file) do not depend on threads.
#include "src/dag/DagBuilder.h"

#include <algorithm>
#include <bit>
#include <limits>
#include <memory>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "src/dag/MortonOrder.h"
#include "src/dag/NodeTable.h"
#include "src/dag/Reflection.h"
#include "src/util/Error.h"

namespace vdbdag::dag {
namespace {

struct Instance {
    CellCoord cell;  // in units of the level's node size, relative to the origin
    ChildRef ref;
};

struct MortonInstanceLess {
    bool operator()(const Instance& a, const Instance& b) const { return mortonLess(a.cell, b.cell); }
};

int64_t floorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

struct InnerCanonicalForm {
    InnerNode key;
    uint8_t reflection;
    uint8_t invariance;
};

// See step 2 in the file comment.
InnerCanonicalForm canonicalInner(const InnerNode& raw, const std::vector<uint8_t>& childInvariance, bool useSymmetry) {
    if (!useSymmetry) return {raw, 0, 1};
    uint32_t base[8];
    uint8_t tag[8], inv[8];
    for (unsigned j = 0; j < 8; ++j) {
        base[j] = raw[j] & ~7u;
        tag[j] = uint8_t(raw[j] & 7u);
        inv[j] = raw[j] ? childInvariance[childIndex(raw[j])] : 0;
    }
    InnerNode keys[8];
    for (unsigned m = 0; m < 8; ++m)
        for (unsigned j = 0; j < 8; ++j) {
            const unsigned from = j ^ m;
            keys[m][j] = base[from] ? base[from] | canonicalTag(tag[from] ^ m, inv[from]) : 0;
        }
    InnerCanonicalForm form{keys[0], 0, 0};
    for (unsigned m = 0; m < 8; ++m) {
        if (keys[m] < form.key) { form.key = keys[m]; form.reflection = uint8_t(m); }
        if (keys[m] == keys[0]) form.invariance |= uint8_t(1u << m);
    }
    return form;
}

class Builder {
public:
    Builder(const GridTopology& topology, const BuildOptions& options) : topo_(topology), opt_(options) {}

    ReducedDag run() {
        ReducedDag dag;
        if (topo_.empty()) return dag;
        placeRoot(dag);
        brickTable_ = std::make_unique<NodeTable<uint64_t>>(dag.bricks);
        dag_ = &dag;
        dag.inner.resize(dag.log2Size - 2);
        innerInvariance_.resize(dag.log2Size - 2);
        for (unsigned k = 0; k < dag.inner.size(); ++k) innerTables_.emplace_back(std::make_unique<NodeTable<InnerNode>>(dag.inner[k].nodes));
        fullRef_.assign(dag.log2Size + 1, 0);
        dag.svoNodeCount.assign(dag.log2Size - 1, 0);

        std::vector<Instance> level = brickInstances();
        dag.svoNodeCount[0] = level.size();
        for (unsigned s = 3; s <= dag.log2Size; ++s) {
            level = parentInstances(level, s);
            mergeTiles(level, s);
            dag.svoNodeCount[s - 2] = level.size();
        }
        if (level.size() != 1 || !(level[0].cell == CellCoord{0, 0, 0}))
            throw Error("internal error: DAG build did not converge to one root");
        dag.root = level[0].ref;
        countReferences(dag);
        return dag;
    }

private:
    void placeRoot(ReducedDag& dag) {
        for (const Brick& b : topo_.bricks)
            if ((b.x & 3) || (b.y & 3) || (b.z & 3)) throw Error("internal error: brick corner not a multiple of 4");
        for (const Tile& t : topo_.tiles) {
            if (t.log2Size < 3 || t.log2Size > 31) throw Error("tile size 2^" + std::to_string(t.log2Size) + " out of range (8 to 2^31)");
            const int64_t size = int64_t(1) << t.log2Size;
            if ((t.x % size) || (t.y % size) || (t.z % size)) throw Error("internal error: tile not aligned to its size");
        }
        const ActiveBounds box = activeBounds(topo_);
        const int64_t alignment = placementAlignment(topo_);
        unsigned log2 = 3;
        for (int a = 0; a < 3; ++a) {
            dag.origin[a] = opt_.origin ? (*opt_.origin)[a] : floorDiv(box.min[a], alignment) * alignment;
            if (dag.origin[a] % alignment != 0 || dag.origin[a] > box.min[a] || box.min[a] - dag.origin[a] > (int64_t(1) << 33))
                throw Error("root origin must be a multiple of " + std::to_string(alignment) + " at or below the active minimum");
            const uint64_t extent = uint64_t(box.max[a] - dag.origin[a]) + 1;
            while ((uint64_t(1) << log2) < extent) ++log2;
        }
        dag.log2Size = log2;
    }

    CellCoord cellOf(int64_t x, int64_t y, int64_t z, unsigned s) const {
        const auto& o = dag_->origin;
        return {uint32_t(uint64_t(x - o[0]) >> s), uint32_t(uint64_t(y - o[1]) >> s), uint32_t(uint64_t(z - o[2]) >> s)};
    }

    std::vector<Instance> brickInstances() {
        const auto& in = topo_.bricks;
        std::vector<Instance> level(in.size());
        std::vector<BrickCanonicalForm> forms(in.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, in.size(), 4096), [&](const auto& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                level[i].cell = cellOf(in[i].x, in[i].y, in[i].z, 2);
                level[i].ref = uint32_t(i);  // temporarily: input position
            }
        });
        tbb::parallel_sort(level.begin(), level.end(), MortonInstanceLess{});
        tbb::parallel_for(tbb::blocked_range<size_t>(0, in.size(), 4096), [&](const auto& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) forms[i] = canonicalBrick(in[level[i].ref].mask, opt_.symmetry);
        });
        for (size_t i = 0; i < level.size(); ++i) {
            if (i > 0 && level[i].cell == level[i - 1].cell) throw Error("internal error: two bricks at the same position");
            level[i].ref = makeChildRef(insertBrick(forms[i]), forms[i].reflection);
        }
        return level;
    }

    uint32_t insertBrick(const BrickCanonicalForm& form) {
        const size_t before = dag_->bricks.size();
        const uint32_t index = brickTable_->findOrInsert(form.mask);
        if (dag_->bricks.size() != before) brickInvariance_.push_back(form.invariance);
        checkCount(dag_->bricks.size());
        return index;
    }

    uint32_t insertInner(unsigned s, const InnerCanonicalForm& form) {
        auto& nodes = dag_->inner[s - 3].nodes;
        const size_t before = nodes.size();
        const uint32_t index = innerTables_[s - 3]->findOrInsert(form.key);
        if (nodes.size() != before) innerInvariance_[s - 3].push_back(form.invariance);
        checkCount(nodes.size());
        return index;
    }

    static void checkCount(size_t n) {
        if (n > kMaxNodesPerLevel) throw Error("too many unique nodes in one DAG level (limit 2^29)");
    }

    const std::vector<uint8_t>& invarianceOf(unsigned s) const { return s == 2 ? brickInvariance_ : innerInvariance_[s - 3]; }

    // Groups the level below (s-1) into the instances of level s.
    std::vector<Instance> parentInstances(const std::vector<Instance>& children, unsigned s) {
        std::vector<Instance> parents;
        std::vector<InnerNode> raw;
        parents.reserve(children.size() / 2 + 1);
        raw.reserve(children.size() / 2 + 1);
        for (size_t i = 0; i < children.size();) {
            const CellCoord parent = parentCell(children[i].cell);
            InnerNode node{};
            for (; i < children.size() && parentCell(children[i].cell) == parent; ++i) node[childSlot(children[i].cell)] = children[i].ref;
            parents.push_back({parent, 0});
            raw.push_back(node);
        }
        std::vector<InnerCanonicalForm> forms(raw.size());
        const auto& childInv = invarianceOf(s - 1);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, raw.size(), 2048), [&](const auto& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) forms[i] = canonicalInner(raw[i], childInv, opt_.symmetry);
        });
        for (size_t i = 0; i < parents.size(); ++i) parents[i].ref = makeChildRef(insertInner(s, forms[i]), forms[i].reflection);
        return parents;
    }

    // The (shared) solid node of level s: an active tile, one uniform cube
    // carrying a single attribute. It has no children (key all zero, which no
    // other node has) and every reflection leaves it unchanged.
    ChildRef solidNodeRef(unsigned s) {
        if (!fullRef_[s]) fullRef_[s] = makeChildRef(insertInner(s, {InnerNode{}, 0, uint8_t(opt_.symmetry ? 0xFF : 1)}), 0);
        return fullRef_[s];
    }

    // Adds the active tiles of exactly level s, keeping Morton order.
    void mergeTiles(std::vector<Instance>& level, unsigned s) {
        std::vector<Instance> tiles;
        for (const Tile& t : topo_.tiles)
            if (t.log2Size == s) tiles.push_back({cellOf(t.x, t.y, t.z, s), 0});
        if (tiles.empty()) return;
        std::sort(tiles.begin(), tiles.end(), MortonInstanceLess{});
        const ChildRef full = solidNodeRef(s);
        for (auto& t : tiles) t.ref = full;
        std::vector<Instance> merged(level.size() + tiles.size());
        std::merge(level.begin(), level.end(), tiles.begin(), tiles.end(), merged.begin(), MortonInstanceLess{});
        for (size_t i = 1; i < merged.size(); ++i)
            if (merged[i].cell == merged[i - 1].cell) throw Error("input topology has overlapping tiles or bricks");
        level = std::move(merged);
    }

    static void countReferences(ReducedDag& dag) {
        dag.brickRefcount.assign(dag.bricks.size(), 0);
        for (auto& l : dag.inner) l.refcount.assign(l.nodes.size(), 0);
        dag.inner.back().refcount[childIndex(dag.root)] = 1;
        for (size_t k = dag.inner.size(); k-- > 0;) {
            const InnerLevel& level = dag.inner[k];
            std::vector<uint64_t>& below = k == 0 ? dag.brickRefcount : dag.inner[k - 1].refcount;
            for (size_t n = 0; n < level.nodes.size(); ++n) {
                if (level.refcount[n] == 0) continue;
                for (ChildRef c : level.nodes[n])
                    if (c) ++below[childIndex(c)];
            }
        }
    }

    const GridTopology& topo_;
    const BuildOptions& opt_;
    ReducedDag* dag_ = nullptr;
    std::unique_ptr<NodeTable<uint64_t>> brickTable_;
    std::vector<std::unique_ptr<NodeTable<InnerNode>>> innerTables_;
    std::vector<uint8_t> brickInvariance_;
    std::vector<std::vector<uint8_t>> innerInvariance_;
    std::vector<ChildRef> fullRef_;
};

} // namespace

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
    return Builder(topology, options).run();
}

} // namespace vdbdag::dag
