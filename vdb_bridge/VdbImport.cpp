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
#include "vdb_bridge/detail/NormalEstimation.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFile.h"

namespace vdbdag::bridge {
namespace {

// Raw bytes of a value (bool as one byte), so values round-trip bit-exactly.
template <typename T>
void appendValue(std::vector<uint8_t>& out, const T& value) {
    if constexpr (std::is_same_v<T, bool>) {
        out.push_back(value ? 1 : 0);
    } else {
        const auto* p = reinterpret_cast<const uint8_t*>(&value);
        out.insert(out.end(), p, p + sizeof(T));
    }
}

template <typename T>
bool sameBits(const T& a, const T& b) {
    if constexpr (std::is_same_v<T, bool>) return a == b;
    else return std::memcmp(&a, &b, sizeof(T)) == 0;
}

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
            for (int b = 0; b < 8; ++b) {
                const int bx = (b & 1) * 4, by = ((b >> 1) & 1) * 4, bz = ((b >> 2) & 1) * 4;
                uint64_t activeMask = 0, inactiveMask = 0;
                for (int bit = 0; bit < 64; ++bit) {
                    const int x = bx + (bit & 3), y = by + ((bit >> 2) & 3), z = bz + (bit >> 4);
                    const openvdb::Index n = openvdb::Index((x << 6) | (y << 3) | z);
                    if (leaf.isValueOn(n)) {
                        activeMask |= uint64_t(1) << bit;
                        if constexpr (hasValues) appendValue(out.activeValues, leaf.getValue(n));
                    } else if constexpr (hasValues) {
                        if (!sameBits(leaf.getValue(n), background)) {
                            inactiveMask |= uint64_t(1) << bit;
                            appendValue(out.inactiveValues, leaf.getValue(n));
                        }
                    }
                }
                const int32_t cx = origin.x() + bx, cy = origin.y() + by, cz = origin.z() + bz;
                if (activeMask) out.active.push_back({cx, cy, cz, activeMask});
                if (inactiveMask) out.inactive.push_back({cx, cy, cz, inactiveMask});
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
            if constexpr (hasValues) appendValue(record.values.tiles, *it);
        } else if constexpr (hasValues) {
            if (!sameBits(ValueT(*it), background)) {
                record.inactiveTopology.tiles.push_back(tile);
                appendValue(record.inactiveValues.tiles, *it);
            }
        }
    }
    if constexpr (hasValues) appendValue(record.background, background);
}

// Exact normals for `--normals` (NormalEstimation.h): the gradient of float
// and double grids, or the values of the vec3 grid named `normalGrid`.
template <typename GridT>
void addNormals(const GridT& grid, GridRecord& record, const std::string& normalGrid, const std::string& path) {
    using ValueT = typename GridT::ValueType;
    constexpr bool scalar = std::is_same_v<ValueT, float> || std::is_same_v<ValueT, double>;
    constexpr bool vec3 = std::is_same_v<ValueT, openvdb::Vec3s> || std::is_same_v<ValueT, openvdb::Vec3d> || std::is_same_v<ValueT, openvdb::Vec3i>;
    if (normalGrid.empty()) {
        if constexpr (scalar) record.normals = detail::gradientNormals(grid, record.topology);
        return;
    }
    if (grid.getName() != normalGrid) return;
    if constexpr (vec3) record.normals = detail::gridNormals(grid, record.topology);
    else throw Error(path + ": --normal-grid '" + normalGrid + "' has type '" + grid.type() + "', not a vec3 normal grid");
}

} // namespace

ImportResult importVdb(const std::string& path, const ImportOptions& options) {
    // Checked and read whole, in file order (detail/VdbFile.h).
    detail::VdbFileContents contents = detail::readVdbFile(path);
    const openvdb::GridPtrVec* grids = &contents.grids;

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
    result.volume.fileMetadata = detail::serializeMetadata(*contents.metadata);
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
            if (options.normals) addNormals(grid, record, options.normalGrid, path);
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
        result.volume.grids.push_back(std::move(record));
    }
    if (options.normals && std::none_of(result.volume.grids.begin(), result.volume.grids.end(), [](const GridRecord& g) { return g.normals.has_value(); })) {
        if (!options.normalGrid.empty())
            throw Error(path + ": no grid named '" + options.normalGrid + "' among the grids encoded, for --normal-grid");
        throw Error(path + ": --normals needs a float or double grid (a level set) to take the gradient of, or a vec3 normal grid named with --normal-grid");
    }
    return result;
}

} // namespace vdbdag::bridge
