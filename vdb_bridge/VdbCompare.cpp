// Topology and header comparison with OpenVDB alone (independent of the DAG
// code): both grids' topologies are copied into MaskTrees and subtracted with
// OpenVDB's topologyDifference, which counts tiles as their voxels.
#include "vdb_bridge/VdbCompare.h"

#include <set>

#include "src/util/Error.h"
#include "vdb_bridge/detail/MaskGridBuilder.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge {
namespace {

// Metadata OpenVDB's writer recomputes on every write (grid statistics and the
// compression it used) or that only concerns value encoding (the half-float
// flag, irrelevant to topology): not part of what a round trip must keep.
const std::set<std::string> kWriterMetadata = {"file_bbox_min", "file_bbox_max", "file_mem_bytes", "file_voxel_count",
                                               "file_compression", "file_delayed_load", "is_saved_as_half_float"};

openvdb::MaskTree::Ptr topologyTree(const openvdb::GridBase& grid) {
    openvdb::MaskTree::Ptr tree;
    detail::dispatchGridType(grid, [&](const auto& typed, ValueType) {
        tree = std::make_shared<openvdb::MaskTree>(typed.tree(), false, openvdb::TopologyCopy());
    });
    return tree;
}

std::string describeBox(const openvdb::CoordBBox& box) {
    const auto& a = box.min();
    if (box.volume() == 1) return "voxel (" + std::to_string(a.x()) + "," + std::to_string(a.y()) + "," + std::to_string(a.z()) + ")";
    return "tile of " + std::to_string(box.dim().x()) + "^3 at (" + std::to_string(a.x()) + "," + std::to_string(a.y()) + "," + std::to_string(a.z()) + ")";
}

void compareHeaders(size_t index, const openvdb::GridBase& a, const openvdb::GridBase& b, std::vector<std::string>& out) {
    const std::string prefix = "grid " + std::to_string(index) + " '" + a.getName() + "': ";
    if (a.getName() != b.getName()) out.push_back(prefix + "name differs ('" + a.getName() + "' vs '" + b.getName() + "')");
    if (a.getGridClass() != b.getGridClass())
        out.push_back(prefix + "class differs (" + openvdb::GridBase::gridClassToString(a.getGridClass()) + " vs " +
                      openvdb::GridBase::gridClassToString(b.getGridClass()) + ")");
    if (a.transform() != b.transform()) out.push_back(prefix + "transform differs");
    std::set<std::string> names;
    for (auto it = a.beginMeta(); it != a.endMeta(); ++it) names.insert(it->first);
    for (auto it = b.beginMeta(); it != b.endMeta(); ++it) names.insert(it->first);
    for (const std::string& name : names) {
        if (kWriterMetadata.count(name)) continue;
        const auto ma = a[name], mb = b[name];
        if (!ma || !mb) out.push_back(prefix + "metadata '" + name + "' only in " + (ma ? "the first" : "the second"));
        else if (!(*ma == *mb)) out.push_back(prefix + "metadata '" + name + "' differs (" + ma->str() + " vs " + mb->str() + ")");
    }
}

TopologyDifference compareTrees(size_t index, const std::string& name, const openvdb::MaskTree& a, const openvdb::MaskTree& b) {
    TopologyDifference d;
    d.gridIndex = index;
    d.gridName = name;
    openvdb::MaskTree onlyA(a), onlyB(b);
    onlyA.topologyDifference(b);
    onlyB.topologyDifference(a);
    d.onlyInA = onlyA.activeVoxelCount();
    d.onlyInB = onlyB.activeVoxelCount();
    for (auto [tree, label] : {std::pair{&onlyA, "only in the first"}, std::pair{&onlyB, "only in the second"}}) {
        int shown = 0;
        for (auto it = tree->cbeginValueOn(); it && shown < 5; ++it, ++shown) {
            openvdb::CoordBBox box;
            it.getBoundingBox(box);
            d.examples.push_back(describeBox(box) + " active " + label);
        }
    }
    return d;
}

CompareResult compareGridLists(const openvdb::GridPtrVec& a, const openvdb::GridPtrVec& b) {
    CompareResult result;
    if (a.size() != b.size())
        result.headerDifferences.push_back("grid count differs (" + std::to_string(a.size()) + " vs " + std::to_string(b.size()) + ")");
    for (size_t g = 0; g < std::min(a.size(), b.size()); ++g) {
        compareHeaders(g, *a[g], *b[g], result.headerDifferences);
        const auto ta = topologyTree(*a[g]), tb = topologyTree(*b[g]);
        if (!ta || !tb) {
            result.headerDifferences.push_back("grid " + std::to_string(g) + " '" + a[g]->getName() + "': unsupported type '" +
                                               (ta ? b[g] : a[g])->type() + "'");
            continue;
        }
        TopologyDifference d = compareTrees(g, a[g]->getName(), *ta, *tb);
        if (d.onlyInA || d.onlyInB) result.topology.push_back(std::move(d));
    }
    result.identical = result.headerDifferences.empty() && result.topology.empty();
    return result;
}

openvdb::GridPtrVec readAll(const std::string& path) {
    detail::initializeOpenVdb();
    try {
        openvdb::io::File file(path);
        file.open(false);
        openvdb::GridPtrVecPtr grids = file.getGrids();
        file.close();
        return *grids;
    } catch (const std::exception& e) {
        throw Error(path + ": cannot be read as a .vdb file (" + detail::oneLine(e.what()) + ")");
    }
}

} // namespace

CompareResult compareTopology(const std::string& originalPath, const Volume& decoded) {
    const openvdb::GridPtrVec original = readAll(originalPath);
    openvdb::GridPtrVec rebuilt;
    for (size_t g = 0; g < decoded.grids.size(); ++g)
        rebuilt.push_back(detail::buildMaskGrid(decoded.grids[g], originalPath + " (decoded grid " + std::to_string(g) + ")"));
    return compareGridLists(original, rebuilt);
}

CompareResult compareTopologyFiles(const std::string& pathA, const std::string& pathB) {
    return compareGridLists(readAll(pathA), readAll(pathB));
}

} // namespace vdbdag::bridge
