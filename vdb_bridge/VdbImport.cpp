// .vdb -> Volume: grid headers (with OpenVDB's own serialisation of an empty
// copy of each grid as the descriptor) and active topology as 4^3 bricks plus
// active tiles, which are never expanded into voxels.
#include "vdb_bridge/VdbImport.h"

#include <algorithm>
#include <cstring>
#include <type_traits>
#include <filesystem>
#include <sstream>

#include <openvdb/openvdb.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/parallel_for.h>

#include "src/util/Error.h"
#include "vdb_bridge/detail/ImportGrids.h"
#include "vdb_bridge/detail/LeafBricks.h"
#include "vdb_bridge/detail/NormalEstimation.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFile.h"

namespace vdbdag::bridge {
namespace {

// Per leaf: its 4^3 bricks of active voxels and of inactive voxels whose
// value is not (bitwise) the background, each with its values.
struct LeafLayers {
    std::vector<Brick> active, inactive;
    std::vector<uint8_t> activeValues, inactiveValues;
};

template <typename GridT, bool hasValues = !std::is_same_v<typename GridT::TreeType::LeafNodeType::BuildType, openvdb::ValueMask>>
void collectLayers(const GridT& grid, GridRecord& record) {
    using TreeT = typename GridT::TreeType;
    using ValueT = typename GridT::ValueType;
    using LeafT = typename TreeT::LeafNodeType;
    const TreeT& tree = grid.tree();
    const ValueT background = tree.background();
    std::vector<const typename TreeT::LeafNodeType*> leaves;
    leaves.reserve(tree.leafCount());
    for (auto it = tree.cbeginLeaf(); it; ++it) leaves.push_back(it.getLeaf());
    std::vector<LeafLayers> perLeaf(leaves.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 64), [&](const auto& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            const auto& leaf = *leaves[i];
            const openvdb::Coord origin = leaf.origin();
            LeafLayers& out = perLeaf[i];
            for (unsigned b = 0; b < 8; ++b) {
                const openvdb::Coord c = detail::brickCorner(origin, b);
                const uint64_t activeMask = detail::leafBrick<LeafT, hasValues>(leaf, b, Layer::Active, background, &out.activeValues);
                const uint64_t inactiveMask = detail::leafBrick<LeafT, hasValues>(leaf, b, Layer::Inactive, background, &out.inactiveValues);
                if (activeMask) out.active.push_back({c.x(), c.y(), c.z(), activeMask});
                if (inactiveMask) out.inactive.push_back({c.x(), c.y(), c.z(), inactiveMask});
            }
        }
    });
    for (const LeafLayers& l : perLeaf) {
        record.topology.bricks.insert(record.topology.bricks.end(), l.active.begin(), l.active.end());
        record.values.bricks.insert(record.values.bricks.end(), l.activeValues.begin(), l.activeValues.end());
        record.inactiveTopology.bricks.insert(record.inactiveTopology.bricks.end(), l.inactive.begin(), l.inactive.end());
        record.inactiveValues.bricks.insert(record.inactiveValues.bricks.end(), l.inactiveValues.begin(), l.inactiveValues.end());
    }
    // Tiles at every level above the leaves (voxels are not visited): active
    // ones, and inactive ones whose value is not the background.
    typename TreeT::ValueAllCIter it = tree.cbeginValueAll();
    it.setMaxDepth(TreeT::ValueAllCIter::LEAF_DEPTH - 1);
    for (; it; ++it) {
        if (!it.isTileValue()) continue;
        const openvdb::CoordBBox box = it.getBoundingBox();
        const Tile tile{box.min().x(), box.min().y(), box.min().z(), uint8_t(std::countr_zero(unsigned(box.dim().x())))};
        if (it.isValueOn()) {
            record.topology.tiles.push_back(tile);
            if constexpr (hasValues) detail::appendValue(record.values.tiles, *it);
        } else if constexpr (hasValues) {
            if (!detail::sameBits(ValueT(*it), background)) {
                record.inactiveTopology.tiles.push_back(tile);
                detail::appendValue(record.inactiveValues.tiles, *it);
            }
        }
    }
    if constexpr (hasValues) detail::appendValue(record.background, background);
}

// Exact normals for `--normals` (NormalEstimation.h): the gradient of float
// and double grids, or the values of the vec3 grid named `normalGrid`.
template <typename GridT>
void addNormals(const GridT& grid, GridRecord& record, const ImportOptions& options, const std::string& path) {
    using ValueT = typename GridT::ValueType;
    constexpr bool scalar = std::is_same_v<ValueT, float> || std::is_same_v<ValueT, double>;
    constexpr bool vec3 = std::is_same_v<ValueT, openvdb::Vec3s> || std::is_same_v<ValueT, openvdb::Vec3d> || std::is_same_v<ValueT, openvdb::Vec3i>;
    const detail::NormalsOf kind = detail::normalsOf(grid, options, path);
    if constexpr (scalar)
        if (kind == detail::NormalsOf::Gradient) record.normals = detail::gradientNormals(grid, record.topology);
    if constexpr (vec3)
        if (kind == detail::NormalsOf::Vectors) record.normals = detail::gridNormals(grid, record.topology);
}

} // namespace

ImportResult importVdb(const std::string& path, const ImportOptions& options) {
    // Checked and read whole, in file order (detail/VdbFile.h).
    const detail::VdbFileContents contents = detail::readVdbFile(path);
    return detail::importGrids(contents.grids, *contents.metadata, path, options);
}

ImportResult detail::importGrids(const openvdb::GridPtrVec& fileGrids, const openvdb::MetaMap& metadata, const std::string& path,
                                 const ImportOptions& options) {
    const openvdb::GridPtrVec* grids = &fileGrids;

    if (!options.onlyGrids.empty()) {
        for (const std::string& wanted : options.onlyGrids) {
            const bool found = std::any_of(grids->begin(), grids->end(), [&](const auto& g) { return g->getName() == wanted; });
            if (!found) {
                std::string names;
                for (const auto& g : *grids) names += (names.empty() ? "'" : ", '") + g->getName() + "'";
                throw Error(path + ": no grid named '" + wanted + "' (the file has " + (names.empty() ? "no grids" : names) + ")");
            }
        }
    }

    ImportResult result;
    result.volume.fileMetadata = detail::serializeMetadata(metadata);
    for (size_t index = 0; index < grids->size(); ++index) {
        const openvdb::GridBase::Ptr& base = (*grids)[index];
        if (!options.onlyGrids.empty() &&
            std::find(options.onlyGrids.begin(), options.onlyGrids.end(), base->getName()) == options.onlyGrids.end())
            continue;
        GridRecord record;
        record.name = base->getName();
        record.gridClass = openvdb::GridBase::gridClassToString(base->getGridClass());
        const bool supported = detail::dispatchGridType(*base, [&](const auto& grid, ValueType type) {
            if (options.topologyOnly) {
                record.valueType = ValueType::Mask;
                collectLayers<std::decay_t<decltype(grid)>, false>(grid, record);
            } else {
                record.valueType = type;
                collectLayers(grid, record);
            }
            if (options.normals) addNormals(grid, record, options, path);
        });
        if (!supported) {
            const std::string message = "grid " + std::to_string(index) + " '" + base->getName() + "' has type '" + base->type() + "'" +
                                        detail::typeHint(*base) + ", which vdbdag does not convert";
            if (!options.skipUnsupported) throw Error(path + ": " + message + " (use --skip-unsupported to convert the other grids)");
            result.warnings.push_back(path + ": skipped " + message);
            continue;
        }
        record.indexToWorld = detail::indexToWorldOf(*base);
        record.vdbDescriptor = detail::descriptorOf(*base);
        record.rescale = detail::rescaleOf(*base);
        result.volume.grids.push_back(std::move(record));
    }
    if (options.normals)
        detail::requireSomeNormals(std::any_of(result.volume.grids.begin(), result.volume.grids.end(), [](const GridRecord& g) { return g.normals.has_value(); }),
                                   options, path);
    return result;
}

detail::NormalsOf detail::normalsOf(const openvdb::GridBase& grid, const ImportOptions& options, const std::string& path) {
    if (!options.normals) return NormalsOf::None;
    const bool scalar = grid.isType<openvdb::FloatGrid>() || grid.isType<openvdb::DoubleGrid>();
    const bool vec3 = grid.isType<openvdb::Vec3SGrid>() || grid.isType<openvdb::Vec3DGrid>() || grid.isType<openvdb::Vec3IGrid>();
    if (options.normalGrid.empty()) return scalar ? NormalsOf::Gradient : NormalsOf::None;
    if (grid.getName() != options.normalGrid) return NormalsOf::None;
    if (!vec3) throw Error(path + ": --normal-grid '" + options.normalGrid + "' has type '" + grid.type() + "', not a vec3 normal grid");
    return NormalsOf::Vectors;
}

void detail::requireSomeNormals(bool found, const ImportOptions& options, const std::string& path) {
    if (found) return;
    if (!options.normalGrid.empty()) throw Error(path + ": no grid named '" + options.normalGrid + "' among the grids encoded, for --normal-grid");
    throw Error(path + ": --normals needs a float or double grid (a level set) to take the gradient of, or a vec3 normal grid named with --normal-grid");
}

} // namespace vdbdag::bridge
