// Comparison with OpenVDB alone (independent of the DAG code): both grids'
// topologies are copied into MaskTrees and subtracted with OpenVDB's
// topologyDifference (tiles count as their voxels); values are compared bit
// for bit leaf by leaf and tile by tile through OpenVDB's accessors.
#include "vdb_bridge/VdbCompare.h"

#include <cstring>
#include <type_traits>

#include "src/util/Error.h"
#include "vdb_bridge/detail/GridBuilder.h"
#include "vdb_bridge/detail/HeaderCompare.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFile.h"

namespace vdbdag::bridge {
namespace {

template <typename T>
bool sameBits(const T& a, const T& b) {
    if constexpr (std::is_same_v<T, bool>) return a == b;
    else return std::memcmp(&a, &b, sizeof(T)) == 0;
}

template <typename GridT>
void compareValues(const GridT& a, const GridT& b, ValueDifference& d) {
    using TreeT = typename GridT::TreeType;
    const TreeT &ta = a.tree(), &tb = b.tree();
    auto accA = a.getConstAccessor();
    auto accB = b.getConstAccessor();
    auto record = [&](const openvdb::Coord& c, const auto& va, const auto& vb, bool active) {
        (active ? d.activeValues : d.inactiveValues)++;
        if (d.examples.size() < 8)
            d.examples.push_back(std::string(active ? "active" : "inactive") + " value at (" + std::to_string(c.x()) + "," + std::to_string(c.y()) + "," +
                                 std::to_string(c.z()) + "): " + detail::showValue(va) + " vs " + detail::showValue(vb));
    };
    // Leaves of A against B (B's leaf, or the tile/background covering it).
    for (auto leaf = ta.cbeginLeaf(); leaf; ++leaf) {
        const auto* other = tb.probeConstLeaf(leaf->origin());
        for (openvdb::Index n = 0; n < TreeT::LeafNodeType::SIZE; ++n) {
            const openvdb::Coord c = leaf->offsetToGlobalCoord(n);
            const auto va = leaf->getValue(n);
            const auto vb = other ? other->getValue(n) : accB.getValue(c);
            const bool active = leaf->isValueOn(n) || (other ? other->isValueOn(n) : accB.isValueOn(c));
            if (!sameBits(va, vb)) record(c, va, vb, active);
        }
    }
    // Leaves of B where A has none.
    for (auto leaf = tb.cbeginLeaf(); leaf; ++leaf) {
        if (ta.probeConstLeaf(leaf->origin())) continue;
        for (openvdb::Index n = 0; n < TreeT::LeafNodeType::SIZE; ++n) {
            const openvdb::Coord c = leaf->offsetToGlobalCoord(n);
            const auto va = accA.getValue(c);
            const auto vb = leaf->getValue(n);
            if (!sameBits(va, vb)) record(c, va, vb, leaf->isValueOn(n) || accA.isValueOn(c));
        }
    }
    // Tiles of each against the other, where the other has no leaf.
    for (int pass = 0; pass < 2; ++pass) {
        const TreeT& from = pass == 0 ? ta : tb;
        auto& otherAcc = pass == 0 ? accB : accA;
        typename TreeT::ValueAllCIter it = from.cbeginValueAll();
        it.setMaxDepth(TreeT::ValueAllCIter::LEAF_DEPTH - 1);
        for (; it; ++it) {
            if (!it.isTileValue()) continue;
            const openvdb::Coord c = it.getCoord();
            if (otherAcc.probeConstLeaf(c)) continue;  // compared voxel by voxel above
            const auto v = *it;
            const auto w = otherAcc.getValue(c);
            if (!sameBits(v, w)) record(c, pass == 0 ? v : w, pass == 0 ? w : v, it.isValueOn() || otherAcc.isValueOn(c));
        }
    }
}

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

void compareGridValues(size_t index, const openvdb::GridBase& a, const openvdb::GridBase& b, CompareResult& result) {
    if (a.type() != b.type()) {
        result.headerDifferences.push_back("grid " + std::to_string(index) + " '" + a.getName() + "': type differs (" + a.type() + " vs " + b.type() + ")");
        return;
    }
    ValueDifference d;
    d.gridIndex = index;
    d.gridName = a.getName();
    detail::dispatchGridType(a, [&](const auto& typed, ValueType type) {
        using GridT = std::decay_t<decltype(typed)>;
        const auto& other = static_cast<const GridT&>(b);
        if (type != ValueType::Mask) {
            if (!sameBits(typed.background(), other.background()))
                result.headerDifferences.push_back("grid " + std::to_string(index) + " '" + a.getName() + "': background differs");
            compareValues(typed, other, d);
        }
    });
    if (d.activeValues || d.inactiveValues) result.values.push_back(std::move(d));
}

CompareResult compareGridLists(const openvdb::GridPtrVec& a, const openvdb::GridPtrVec& b, bool values) {
    CompareResult result;
    if (a.size() != b.size())
        result.headerDifferences.push_back("grid count differs (" + std::to_string(a.size()) + " vs " + std::to_string(b.size()) + ")");
    for (size_t g = 0; g < std::min(a.size(), b.size()); ++g) {
        detail::compareHeaders(g, *a[g], *b[g], result.headerDifferences);
        const auto ta = topologyTree(*a[g]), tb = topologyTree(*b[g]);
        if (!ta || !tb) {
            result.headerDifferences.push_back("grid " + std::to_string(g) + " '" + a[g]->getName() + "': unsupported type '" +
                                               (ta ? b[g] : a[g])->type() + "'");
            continue;
        }
        TopologyDifference d = compareTrees(g, a[g]->getName(), *ta, *tb);
        if (d.onlyInA || d.onlyInB) result.topology.push_back(std::move(d));
        if (values) compareGridValues(g, *a[g], *b[g], result);
    }
    result.identical = result.headerDifferences.empty() && result.topology.empty() && result.values.empty();
    return result;
}

void finish(CompareResult& result) {
    result.identical = result.headerDifferences.empty() && result.topology.empty() && result.values.empty();
}

} // namespace

CompareResult compareWithFile(const std::string& originalPath, const Volume& decoded, bool values) {
    const detail::VdbFileContents original = detail::readVdbFile(originalPath);
    openvdb::GridPtrVec rebuilt;
    for (size_t g = 0; g < decoded.grids.size(); ++g)
        rebuilt.push_back(detail::buildGrid(decoded.grids[g], originalPath + " (decoded grid " + std::to_string(g) + ")"));
    CompareResult result = compareGridLists(original.grids, rebuilt, values);
    detail::compareFileMetadata(*original.metadata, *detail::parseMetadata(decoded.fileMetadata, originalPath + " (decoded)"), result.headerDifferences);
    finish(result);
    return result;
}

CompareResult compareFiles(const std::string& pathA, const std::string& pathB, bool values) {
    const detail::VdbFileContents a = detail::readVdbFile(pathA), b = detail::readVdbFile(pathB);
    CompareResult result = compareGridLists(a.grids, b.grids, values);
    detail::compareFileMetadata(*a.metadata, *b.metadata, result.headerDifferences);
    finish(result);
    return result;
}

} // namespace vdbdag::bridge
