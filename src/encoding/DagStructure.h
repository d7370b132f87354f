// The sharing structure of a compact DAG, for showing it (`vdbdag export
// --structure`): per level, every stored (unique) node with its reference
// count (parent pointers to it), its instance count (how often it appears in
// the expanded octree) and the placement of its first instance; and a walk
// over every node instance with the reflection under which it uses the
// shared node (SSVDAG paper §3: a child instance is the stored node reflected
// by the XOR of the pointer tags above it, DESIGN.md invariant 2).
// Pure core: no VTK here, the writer lives in vdb_bridge/VtkStructure.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "src/encoding/CompactDag.h"

namespace vdbdag::encoding {

struct StructureLevel {
    unsigned log2Size = 0;              // nodes here are 2^log2Size voxels wide (2 = 4^3 bricks)
    std::vector<uint64_t> refcount;     // per node id: parent pointers to it (the root: 1, the grid's reference)
    std::vector<uint64_t> instances;    // per node id: instances in the expanded tree (saturating at 2^64-1)
    std::vector<bool> solid;            // per node id: a solid node (an active tile), inner levels only
    // First instance of each node in level order: minimum corner (index space) and reflection.
    std::vector<std::array<int64_t, 3>> firstCorner;
    std::vector<uint8_t> firstMirror;
    uint64_t totalInstances = 0;        // sum of `instances` (saturating)
    uint64_t nodeCount() const { return refcount.size(); }
};

// Levels root first (log2Size = dag.log2Size down to 2). Node ids are the
// nodes' ordinals within their level in stored order (by reference count,
// most referenced first). Empty for an empty DAG. The DAG must be validated.
std::vector<StructureLevel> analyzeStructure(const CompactDag& dag);

struct NodeInstance {
    unsigned levelIndex;  // 0 = root level
    unsigned log2Size;
    uint32_t nodeId;
    int64_t x, y, z;      // minimum corner, index space
    unsigned mirror;      // accumulated reflection of this instance (bit 0 x, 1 y, 2 z)
};

// Every node instance, depth-first from the root (parents before children).
void visitNodeInstances(const CompactDag& dag, const std::function<void(const NodeInstance&)>& visit);

} // namespace vdbdag::encoding
