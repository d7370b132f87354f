// The reduced DAG as the builder produces it, before compact encoding: for
// every level, the unique nodes (representatives) with their child references
// and reference counts. Level numbering is by node size: level s holds nodes
// covering 2^s voxels per axis; s = 2 are the 4^3 bricks, s = log2Size the root.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vdbdag::dag {

// A reference to a node of the level below: 0 = no child, otherwise
// (nodeIndex + 1) << 3 | reflection. The instance is reflectBrick/reflect of
// the stored representative by `reflection` (SSVDAG paper §3).
using ChildRef = uint32_t;
constexpr ChildRef makeChildRef(uint32_t nodeIndex, unsigned reflection) { return ((nodeIndex + 1) << 3) | reflection; }
constexpr uint32_t childIndex(ChildRef ref) { return (ref >> 3) - 1; }
constexpr unsigned childReflection(ChildRef ref) { return ref & 7u; }
constexpr uint32_t kMaxNodesPerLevel = (1u << 29) - 2;

using InnerNode = std::array<ChildRef, 8>;  // by stored child slot; all 0 = solid node (an active tile)

struct InnerLevel {
    std::vector<InnerNode> nodes;
    std::vector<uint64_t> refcount;  // references from reachable parents
};

struct ReducedDag {
    std::array<int64_t, 3> origin{0, 0, 0};  // index coordinate of the root cube's minimum corner
    unsigned log2Size = 0;                   // root cube is 2^log2Size voxels wide; 0 = empty grid
    ChildRef root = 0;                       // reference to the root (in inner[log2Size-3]); 0 = empty

    std::vector<uint64_t> bricks;          // canonical 4^3 masks (level 2)
    std::vector<uint64_t> brickRefcount;
    std::vector<InnerLevel> inner;         // inner[k] holds level s = k + 3

    // Per level s = 2..log2Size (index s - 2): nodes in the sparse voxel
    // octree this DAG replaces (active tiles count as one node each).
    std::vector<uint64_t> svoNodeCount;

    bool empty() const { return root == 0; }
    size_t levelCount() const { return log2Size == 0 ? 0 : log2Size - 1; }  // including bricks
    uint64_t uniqueNodeCount(unsigned s) const {
        return s == 2 ? bricks.size() : inner[s - 3].nodes.size();
    }
};

} // namespace vdbdag::dag
