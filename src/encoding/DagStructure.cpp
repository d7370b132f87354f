// Sharing structure of a compact DAG: node ids, reference and instance
// counts computed level by level (pointers only go from level i to i+1, so
// one top-down pass per level suffices), and the instance walk.
#include "src/encoding/DagStructure.h"

#include "src/encoding/DagDescent.h"

#include <algorithm>
#include <limits>

#include "src/util/Error.h"

namespace vdbdag::encoding {
namespace {

uint64_t saturatingAdd(uint64_t a, uint64_t b) { return a > std::numeric_limits<uint64_t>::max() - b ? std::numeric_limits<uint64_t>::max() : a + b; }

// Word offsets (relative to the level start) of the nodes of inner level i, in stored order.
std::vector<uint64_t> nodeStarts(const CompactDag& dag, size_t i) {
    std::vector<uint64_t> starts;
    forEachNode(dag, i, [&](uint64_t pos, uint16_t) { starts.push_back(pos - dag.levelStart[i]); });
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
        for (uint32_t id = 0; id < level.nodeCount(); ++id) {
            const uint64_t pos = dag.levelStart[i] + starts[i][id];
            if (dag.inner[pos] == 0) { level.solid[id] = true; continue; }
            const auto& c = level.firstCorner[id];
            const NodePlace first{c[0], c[1], c[2], level.firstMirror[id]};
            forEachPlacedChild(dag, i, pos, level.log2Size, first, [&](const ChildPointer& ptr, const NodePlace& at) {
                const uint32_t child = i + 1 < innerCount ? idOf(starts[i + 1], ptr.offset) : uint32_t(ptr.offset);
                below.refcount[child] += 1;
                below.instances[child] = saturatingAdd(below.instances[child], level.instances[id]);
                if (!placed[child] && level.instances[id] > 0) {
                    placed[child] = true;
                    below.firstCorner[child] = {at.x, at.y, at.z};
                    below.firstMirror[child] = uint8_t(at.mirror);
                }
            });
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

    descend(
        dag,
        [&](size_t i, uint64_t offset, uint16_t, const NodePlace& at) {
            visit(NodeInstance{unsigned(i), dag.log2Size - unsigned(i), idOf(starts[i], offset), at.x, at.y, at.z, at.mirror});
            return true;
        },
        [&](uint64_t leaf, const NodePlace& at) { visit(NodeInstance{unsigned(innerCount), 2, uint32_t(leaf), at.x, at.y, at.z, at.mirror}); });
}

} // namespace vdbdag::encoding
