// The walks over a compact DAG's words (CompactDag.h), written once for the
// loops that read a whole DAG: the validator, the sizes and facts computed
// bottom-up, the sharing statistics, the bounds, the tracer's occupied box
// and the depth-first walk in attribute order (DESIGN.md invariant 2) that
// every decode takes. The per-word decoding (tags, pointers, node sizes) is
// include/vdbdag/dag_access.h, shared with the reader and the shaders; this
// header adds what only whole-DAG C++ loops need, as templates (no
// std::function per node).
//
//   forEachNode        the nodes of one inner level, in stored order
//   forEachStoredChild a node's stored children, in stored slot order (the
//                      attribute order), with their pointers
//   forEachPlacedChild the same with each child's place: its corner and the
//                      mirror the walk reaches it with
//   descend            depth-first from the root (descendFrom: from any
//                      node), in attribute order: an inner node's callback
//                      says whether to enter it
//
// Every walk assumes a validated DAG (validateCompact), except that
// forEachNode only needs each level's node boundaries to be whole, which
// validateCompact checks first (its pass 1 walks the words itself).
#pragma once
#include <cstdint>

#include <vdbdag/dag_access.h>

#include "src/encoding/CompactDag.h"

namespace vdbdag::encoding {

// Where a node instance lies: its minimum corner in index space and the
// mirror (bit a: axis a reflected) of the path that reaches it.
struct NodePlace {
    int64_t x = 0, y = 0, z = 0;
    unsigned mirror = 0;
};

// The root's place: the DAG's origin and root reflection.
inline NodePlace rootPlace(const CompactDag& dag) { return {dag.origin[0], dag.origin[1], dag.origin[2], dag.rootReflection}; }

// visit(pos, header) for each node of inner level `level`, in stored order
// (pos: the node's word in dag.inner).
template <typename Visit>
void forEachNode(const CompactDag& dag, size_t level, Visit&& visit) {
    const uint64_t end = dag.levelEnd(level);
    for (uint64_t pos = dag.levelStart[level]; pos < end; pos += access::dagNodeWords(dag.inner[pos], dag.offsetWords[level])) visit(pos, dag.inner[pos]);
}

// visit(slot, pointer) for each stored child of the node at word `pos` of
// inner level `level`, in stored slot order; none for a solid node.
template <typename Visit>
void forEachStoredChild(const CompactDag& dag, size_t level, uint64_t pos, Visit&& visit) {
    const unsigned header = dag.inner[pos];
    for (unsigned j = 0; j < 8; ++j)
        if (access::dagChildTag(header, j) != 0) visit(j, readChild(dag.inner, pos, j, dag.offsetWords[level]));
}

// visit(pointer, place) for each stored child of the node at word `pos` of
// inner level `level`, a cube of 2^log2Size voxels at `at`: the child of
// stored slot j lies in the spatial octant j ^ at.mirror and is reached
// with the mirror at.mirror ^ its pointer's reflection.
template <typename Visit>
void forEachPlacedChild(const CompactDag& dag, size_t level, uint64_t pos, unsigned log2Size, const NodePlace& at, Visit&& visit) {
    const int64_t half = int64_t(1) << (log2Size - 1);
    forEachStoredChild(dag, level, pos, [&](unsigned j, const ChildPointer& ptr) {
        const unsigned p = j ^ at.mirror;  // spatial slot
        visit(ptr, NodePlace{at.x + ((p & 1u) ? half : 0), at.y + ((p & 2u) ? half : 0), at.z + ((p & 4u) ? half : 0), at.mirror ^ ptr.reflection});
    });
}

// Depth-first from the node at word `offset` of inner level `level`, placed
// at `at` (descend: from the root), children in stored slot order, so
// leaves and solid nodes come in attribute order.
// inner(level, offset, header, place) for each inner node instance (offset:
// its word within its level; header 0: solid) returns whether to enter it
// (a solid node has nothing to enter); leaf(index, place) for each 4^3
// leaf instance (index into dag.leaves).
template <typename Inner, typename Leaf>
void descendFrom(const CompactDag& dag, size_t level, uint64_t offset, const NodePlace& at, Inner&& inner, Leaf&& leaf) {
    const size_t levels = dag.innerLevelCount();
    auto visit = [&](auto& self, size_t i, uint64_t here, const NodePlace& place) -> void {
        const uint64_t pos = dag.levelStart[i] + here;
        const uint16_t header = dag.inner[pos];
        if (!inner(i, here, header, place) || header == 0) return;
        const bool toLeaves = i + 1 == levels;
        forEachPlacedChild(dag, i, pos, dag.log2Size - unsigned(i), place, [&](const ChildPointer& ptr, const NodePlace& child) {
            if (toLeaves) leaf(ptr.offset, child);
            else self(self, i + 1, ptr.offset, child);
        });
    };
    visit(visit, level, offset, at);
}

template <typename Inner, typename Leaf>
void descend(const CompactDag& dag, Inner&& inner, Leaf&& leaf) {
    if (!dag.empty()) descendFrom(dag, 0, 0, rootPlace(dag), inner, leaf);
}

} // namespace vdbdag::encoding
