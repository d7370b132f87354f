// Sharing structure of a compact DAG: node ids, reference and instance
// counts computed level by level (pointers only go from level i to i+1, so
// one top-down pass per level suffices), and the instance walk.
#include "src/encoding/DagStructure.h"

#include <algorithm>
#include <limits>

#include "src/util/Error.h"

namespace vdbdag::encoding {
namespace {

uint64_t saturatingAdd(uint64_t a, uint64_t b) { return a > std::numeric_limits<uint64_t>::max() - b ? std::numeric_limits<uint64_t>::max() : a + b; }

// Word offsets (relative to the level start) of the nodes of inner level i, in stored order.
std::vector<uint64_t> nodeStarts(const CompactDag& dag, size_t i) {
    std::vector<uint64_t> starts;
    const uint64_t begin = dag.levelStart[i], end = dag.levelEnd(i);
    for (uint64_t pos = begin; pos < end; pos += nodeWordCount(dag.inner[pos], dag.offsetWords[i])) starts.push_back(pos - begin);
    return starts;
}

uint32_t idOf(const std::vector<uint64_t>& starts, uint64_t offset) {
    const auto it = std::lower_bound(starts.begin(), starts.end(), offset);
    if (it == starts.end() || *it != offset) throw Error("DAG pointer does not land on a node start (the DAG was not validated)");
    return uint32_t(it - starts.begin());
}

} // namespace

std::vector<StructureLevel> analyzeStructure(const CompactDag& dag) {
    std::vector<StructureLevel> levels;
    if (dag.empty()) return levels;
    const size_t innerCount = dag.innerLevelCount();
    std::vector<std::vector<uint64_t>> starts(innerCount);
    levels.resize(innerCount + 1);
    for (size_t i = 0; i <= innerCount; ++i) {
        StructureLevel& level = levels[i];
        level.log2Size = dag.log2Size - unsigned(i);
        const size_t n = i < innerCount ? (starts[i] = nodeStarts(dag, i)).size() : dag.leaves.size();
        level.refcount.assign(n, 0);
        level.instances.assign(n, 0);
        level.solid.assign(n, false);
        level.firstCorner.assign(n, {0, 0, 0});
        level.firstMirror.assign(n, 0);
    }
    StructureLevel& root = levels[0];
    root.refcount[0] = 1;
    root.instances[0] = 1;
    root.firstCorner[0] = dag.origin;
    root.firstMirror[0] = dag.rootReflection;
    for (size_t i = 0; i < innerCount; ++i) {
        StructureLevel& level = levels[i];
        StructureLevel& below = levels[i + 1];
        std::vector<bool> placed(below.nodeCount(), false);
        const int64_t half = int64_t(1) << (level.log2Size - 1);
        for (uint32_t id = 0; id < level.nodeCount(); ++id) {
            const uint64_t pos = dag.levelStart[i] + starts[i][id];
            const uint16_t header = dag.inner[pos];
            if (header == 0) { level.solid[id] = true; continue; }
            for (unsigned j = 0; j < 8; ++j) {
                if (((header >> (2 * j)) & 3u) == 0) continue;
                const ChildPointer ptr = readChild(dag.inner, pos, j, dag.offsetWords[i]);
                const uint32_t child = i + 1 < innerCount ? idOf(starts[i + 1], ptr.offset) : uint32_t(ptr.offset);
                below.refcount[child] += 1;
                below.instances[child] = saturatingAdd(below.instances[child], level.instances[id]);
                if (!placed[child] && level.instances[id] > 0) {
                    placed[child] = true;
                    const unsigned mirror = level.firstMirror[id];
                    const unsigned p = j ^ mirror;  // spatial slot of stored slot j
                    const auto& c = level.firstCorner[id];
                    below.firstCorner[child] = {c[0] + ((p & 1u) ? half : 0), c[1] + ((p & 2u) ? half : 0), c[2] + ((p & 4u) ? half : 0)};
                    below.firstMirror[child] = uint8_t(mirror ^ ptr.reflection);
                }
            }
        }
    }
    for (StructureLevel& level : levels)
        for (uint64_t n : level.instances) level.totalInstances = saturatingAdd(level.totalInstances, n);
    return levels;
}

void visitNodeInstances(const CompactDag& dag, const std::function<void(const NodeInstance&)>& visit) {
    if (dag.empty()) return;
    const size_t innerCount = dag.innerLevelCount();
    std::vector<std::vector<uint64_t>> starts(innerCount);
    for (size_t i = 0; i < innerCount; ++i) starts[i] = nodeStarts(dag, i);

    struct Walker {
        const CompactDag& dag;
        const std::vector<std::vector<uint64_t>>& starts;
        const std::function<void(const NodeInstance&)>& visit;
        void inner(size_t i, uint32_t id, unsigned mirror, int64_t x, int64_t y, int64_t z) {
            const unsigned log2Size = dag.log2Size - unsigned(i);
            visit(NodeInstance{unsigned(i), log2Size, id, x, y, z, mirror});
            const uint64_t pos = dag.levelStart[i] + starts[i][id];
            const uint16_t header = dag.inner[pos];
            if (header == 0) return;
            const int64_t half = int64_t(1) << (log2Size - 1);
            const bool toLeaves = i + 1 == starts.size();
            for (unsigned j = 0; j < 8; ++j) {
                if (((header >> (2 * j)) & 3u) == 0) continue;
                const unsigned p = j ^ mirror;
                const ChildPointer ptr = readChild(dag.inner, pos, j, dag.offsetWords[i]);
                const unsigned childMirror = mirror ^ ptr.reflection;
                const int64_t cx = x + ((p & 1u) ? half : 0), cy = y + ((p & 2u) ? half : 0), cz = z + ((p & 4u) ? half : 0);
                if (toLeaves)
                    visit(NodeInstance{unsigned(i + 1), 2, uint32_t(ptr.offset), cx, cy, cz, childMirror});
                else
                    inner(i + 1, idOf(starts[i + 1], ptr.offset), childMirror, cx, cy, cz);
            }
        }
    };
    Walker{dag, starts, visit}.inner(0, 0, dag.rootReflection, dag.origin[0], dag.origin[1], dag.origin[2]);
}

} // namespace vdbdag::encoding
