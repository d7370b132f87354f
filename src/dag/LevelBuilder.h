// The hash-consing state of one DAG under construction and the step that
// raises one level to the next (SSVDAG paper §4.1). Shared by the in-core
// builder (DagBuilder) and the merge of sub-DAGs (SubDagMerge), so both put
// nodes in canonical form and number them the same way.
//
// Numbering rule (what makes the merge give the same DAG as the in-core
// build): at every level, unique nodes are numbered in the order their first
// instance appears in Morton order, active tiles (solid nodes) included.
// Every aligned cube of the grid is a contiguous Morton range, so the nodes
// of a grid split into cubes are the cubes' nodes concatenated in Morton
// order, minus repeats.
#pragma once
#include <memory>
#include <vector>

#include "src/dag/MortonOrder.h"
#include "src/dag/NodeTable.h"
#include "src/dag/ReducedDag.h"
#include "src/dag/Reflection.h"

namespace vdbdag::dag {

// One node instance of a level: where it is and which stored node it is.
struct Instance {
    CellCoord cell;  // in units of the level's node size, relative to the DAG's origin
    ChildRef ref;
};

struct InnerCanonicalForm {
    InnerNode key;          // the smallest key over the 8 reflections
    uint8_t reflection;     // raw node == reflect(key's node, reflection)
    uint8_t invariance;     // reflections that leave the node unchanged
};

// Step 2 of DagBuilder.cpp's comment: `raw` lists the children by slot as
// (index + 1) << 3 | reflection; `childInvariance` are the invariance sets of
// the level below, by node index.
InnerCanonicalForm canonicalInner(const InnerNode& raw, const std::vector<uint8_t>& childInvariance, bool useSymmetry);

class LevelBuilder {
public:
    // Fills `dag.bricks` and `dag.inner` (levels 3 .. dag.log2Size, which
    // must be set) and `dag.svoNodeCount`.
    LevelBuilder(ReducedDag& dag, bool symmetry);

    // Hash-conses one brick mask; returns the instance's reference.
    ChildRef addBrick(uint64_t mask);
    // The same for many bricks, in order (canonical forms in parallel).
    std::vector<ChildRef> addBricks(const std::vector<uint64_t>& masks);
    // Hash-conses a node of level s given by its raw children (see
    // canonicalInner); all-zero = the solid node (an active tile).
    ChildRef addInner(unsigned s, const InnerNode& raw);

    // The instances of level s from those of level s-1 (Morton order) and
    // the active tiles of exactly level s (`tiles`: their cells, any order).
    // Counts the level's octree nodes into svoNodeCount.
    std::vector<Instance> raise(const std::vector<Instance>& children, std::vector<CellCoord> tiles, unsigned s);

    const std::vector<uint8_t>& invarianceOf(unsigned s) const { return s == 2 ? brickInvariance_ : innerInvariance_[s - 3]; }
    bool symmetry() const { return symmetry_; }

private:
    ChildRef insertBrick(const BrickCanonicalForm& form);
    ChildRef insertInner(unsigned s, const InnerCanonicalForm& form);
    ReducedDag& dag_;
    bool symmetry_;
    std::unique_ptr<NodeTable<uint64_t>> brickTable_;
    std::vector<std::unique_ptr<NodeTable<InnerNode>>> innerTables_;
    std::vector<uint8_t> brickInvariance_;
    std::vector<std::vector<uint8_t>> innerInvariance_;
};

// Exact reference counts of every node reachable from dag.root.
void countReferences(ReducedDag& dag);

} // namespace vdbdag::dag
