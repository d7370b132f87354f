// See VdbSummary.h.
#include "vdb_bridge/VdbSummary.h"

#include <limits>

#include <openvdb/tools/Count.h>

#include "vdb_bridge/detail/LeafBricks.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFile.h"

namespace vdbdag::bridge {
namespace {

std::vector<MetadataEntry> entriesOf(const openvdb::MetaMap& map) {
    std::vector<MetadataEntry> out;
    for (auto it = map.beginMeta(); it != map.endMeta(); ++it)
        if (it->second) out.push_back({it->first, it->second->typeName(), it->second->str()});
    return out;
}

GridHeaderFacts factsOf(const openvdb::GridBase& grid, const std::optional<format::IndexBox>& box) {
    GridHeaderFacts f;
    f.treeType = grid.type();
    const openvdb::Vec3d v = grid.voxelSize();
    f.voxelSize = {v[0], v[1], v[2]};
    f.transform = grid.transform().mapType();
    f.metadata = entriesOf(grid);
    auto fits = [](int64_t v) { return v >= std::numeric_limits<int32_t>::min() && v <= std::numeric_limits<int32_t>::max(); };
    if (box && fits(box->min[0]) && fits(box->min[1]) && fits(box->min[2]) && fits(box->max[0]) && fits(box->max[1]) && fits(box->max[2])) {
        const openvdb::CoordBBox index(openvdb::Coord(openvdb::Vec3i(int(box->min[0]), int(box->min[1]), int(box->min[2]))),
                                       openvdb::Coord(openvdb::Vec3i(int(box->max[0]), int(box->max[1]), int(box->max[2]))));
        const openvdb::BBoxd world = grid.transform().indexToWorld(index);
        f.worldBox = std::array<double, 6>{world.min()[0], world.min()[1], world.min()[2], world.max()[0], world.max()[1], world.max()[2]};
    }
    return f;
}

} // namespace

GridHeaderFacts gridHeaderFacts(const GridRecord& record, const std::optional<format::IndexBox>& indexBox, const std::string& what) {
    return factsOf(*detail::readDescriptor(record.vdbDescriptor, what), indexBox);
}

std::vector<MetadataEntry> fileMetadataEntries(const std::vector<uint8_t>& fileMetadata, const std::string& what) {
    if (fileMetadata.empty()) return {};
    return entriesOf(*detail::parseMetadata(fileMetadata, what));
}

VdbFileFacts vdbFileFacts(const std::string& path) {
    detail::VdbFileContents contents = detail::readVdbFile(path);
    VdbFileFacts out;
    out.fileVersion = contents.fileVersion;
    out.fileMetadata = entriesOf(*contents.metadata);
    for (const openvdb::GridBase::Ptr& base : contents.grids) {
        VdbGridFacts g;
        g.header.name = base->getName();
        g.header.gridClass = openvdb::GridBase::gridClassToString(base->getGridClass());
        g.header.indexToWorld = detail::indexToWorldOf(*base);
        const bool supported = detail::dispatchGridType(*base, [&](const auto& grid, ValueType type) {
            using ValueT = typename std::decay_t<decltype(grid)>::ValueType;
            g.header.valueType = type;
            g.summary.activeVoxels = grid.tree().activeVoxelCount();
            g.summary.solidNodes = grid.tree().activeTileCount();
            openvdb::CoordBBox box;
            if (grid.tree().evalActiveVoxelBoundingBox(box))
                g.summary.indexBox = format::IndexBox{{box.min().x(), box.min().y(), box.min().z()}, {box.max().x(), box.max().y(), box.max().z()}};
            if constexpr (!std::is_same_v<ValueT, openvdb::ValueMask>) {
                detail::appendValue(g.header.background, grid.background());
                if (g.summary.activeVoxels) {
                    const openvdb::math::MinMax<ValueT> range = openvdb::tools::minMax(grid.tree());
                    detail::appendValue(g.summary.activeRange.min, range.min());
                    detail::appendValue(g.summary.activeRange.max, range.max());
                }
            }
        });
        g.facts = factsOf(*base, g.summary.indexBox);
        if (!supported)
            throw Error(path + ": grid '" + base->getName() + "' has type '" + base->type() + "'" + detail::typeHint(*base) + ", which vdbdag does not read");
        out.grids.push_back(std::move(g));
    }
    return out;
}

} // namespace vdbdag::bridge
