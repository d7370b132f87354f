// See LevelBuilder.h; the canonical forms are explained in DagBuilder.cpp.
#include "src/dag/LevelBuilder.h"

#include "src/dag/BuildParallel.h"

#include <algorithm>
#include <string>


#include "src/util/Error.h"

namespace vdbdag::dag {
namespace {

void checkCount(size_t n) {
    if (n > kMaxNodesPerLevel) throw Error("too many unique nodes in one DAG level (limit 2^29)");
}

struct MortonInstanceLess {
    bool operator()(const CellCoord& a, const CellCoord& b) const { return mortonLess(a, b); }
};

} // namespace

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

LevelBuilder::LevelBuilder(ReducedDag& dag, bool symmetry) : dag_(dag), symmetry_(symmetry) {
    if (dag.log2Size < 3) throw Error("internal error: a DAG needs at least one inner level");
    brickTable_ = std::make_unique<NodeTable<uint64_t>>(dag.bricks);
    dag.inner.resize(dag.log2Size - 2);
    innerInvariance_.resize(dag.log2Size - 2);
    for (auto& level : dag.inner) innerTables_.emplace_back(std::make_unique<NodeTable<InnerNode>>(level.nodes));
    dag.svoNodeCount.assign(dag.log2Size - 1, 0);
}

ChildRef LevelBuilder::addBrick(uint64_t mask) { return insertBrick(canonicalBrick(mask, symmetry_)); }

std::vector<ChildRef> LevelBuilder::addBricks(const std::vector<uint64_t>& masks) {
    std::vector<BrickCanonicalForm> forms(masks.size());
    detail::forEachRange(masks.size(), 4096, [&](size_t begin, size_t end) {
        for (size_t i = begin; i != end; ++i) forms[i] = canonicalBrick(masks[i], symmetry_);
    });
    std::vector<ChildRef> refs(masks.size());
    for (size_t i = 0; i < masks.size(); ++i) refs[i] = insertBrick(forms[i]);
    return refs;
}

ChildRef LevelBuilder::insertBrick(const BrickCanonicalForm& form) {
    const size_t before = dag_.bricks.size();
    const uint32_t index = brickTable_->findOrInsert(form.mask);
    if (dag_.bricks.size() != before) brickInvariance_.push_back(form.invariance);
    checkCount(dag_.bricks.size());
    return makeChildRef(index, form.reflection);
}

ChildRef LevelBuilder::insertInner(unsigned s, const InnerCanonicalForm& form) {
    auto& nodes = dag_.inner[s - 3].nodes;
    const size_t before = nodes.size();
    const uint32_t index = innerTables_[s - 3]->findOrInsert(form.key);
    if (nodes.size() != before) innerInvariance_[s - 3].push_back(form.invariance);
    checkCount(nodes.size());
    return makeChildRef(index, form.reflection);
}

ChildRef LevelBuilder::addInner(unsigned s, const InnerNode& raw) {
    if (raw == InnerNode{}) return insertInner(s, {raw, 0, uint8_t(symmetry_ ? 0xFF : 1)});
    return insertInner(s, canonicalInner(raw, invarianceOf(s - 1), symmetry_));
}

std::vector<Instance> LevelBuilder::raise(const std::vector<Instance>& children, std::vector<CellCoord> tiles, unsigned s) {
    // Parents of the children, then the tiles merged in Morton order. A
    // solid node's raw form is all zero, which no parent of a child has.
    std::vector<Instance> level;
    std::vector<InnerNode> raw;
    level.reserve(children.size() / 2 + tiles.size() + 1);
    raw.reserve(children.size() / 2 + tiles.size() + 1);
    std::sort(tiles.begin(), tiles.end(), MortonInstanceLess{});
    if (std::adjacent_find(tiles.begin(), tiles.end()) != tiles.end()) throw Error("input topology has overlapping tiles or bricks");
    size_t t = 0;
    for (size_t i = 0; i < children.size();) {
        const CellCoord parent = parentCell(children[i].cell);
        for (; t < tiles.size() && mortonLess(tiles[t], parent); ++t) { level.push_back({tiles[t], 0}); raw.push_back({}); }
        if (t < tiles.size() && tiles[t] == parent) throw Error("input topology has overlapping tiles or bricks");
        InnerNode node{};
        for (; i < children.size() && parentCell(children[i].cell) == parent; ++i) node[childSlot(children[i].cell)] = children[i].ref;
        level.push_back({parent, 0});
        raw.push_back(node);
    }
    for (; t < tiles.size(); ++t) {
        level.push_back({tiles[t], 0});
        raw.push_back({});
    }
    std::vector<InnerCanonicalForm> forms(raw.size());
    const auto& childInv = invarianceOf(s - 1);
    detail::forEachRange(raw.size(), 2048, [&](size_t begin, size_t end) {
        for (size_t i = begin; i != end; ++i)
            forms[i] = raw[i] == InnerNode{} ? InnerCanonicalForm{raw[i], 0, uint8_t(symmetry_ ? 0xFF : 1)}
                                             : canonicalInner(raw[i], childInv, symmetry_);
    });
    for (size_t i = 0; i < level.size(); ++i) level[i].ref = insertInner(s, forms[i]);
    dag_.svoNodeCount[s - 2] += level.size();
    return level;
}

void countReferences(ReducedDag& dag) {
    dag.brickRefcount.assign(dag.bricks.size(), 0);
    for (auto& l : dag.inner) l.refcount.assign(l.nodes.size(), 0);
    if (dag.root == 0) return;
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

} // namespace vdbdag::dag
