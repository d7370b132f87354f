// See GridBuilder.h.
#include "vdb_bridge/detail/GridBuilder.h"

#include <bit>
#include <cstring>

#include "vdb_bridge/detail/LeafBricks.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge::detail {
namespace {

template <typename T>
T valueAt(const std::vector<uint8_t>& bytes, size_t index) {
    return valueFromBytes<T>(&bytes[index * (std::is_same_v<T, bool> ? 1 : sizeof(T))]);
}

template <typename GridT>
void fill(GridT& grid, const GridRecord& record) {
    using ValueT = typename GridT::ValueType;
    constexpr bool hasValues = !std::is_same_v<typename GridT::TreeType::LeafNodeType::BuildType, openvdb::ValueMask>;  // mask grids carry no values
    auto& tree = grid.tree();
    openvdb::tree::ValueAccessor<typename GridT::TreeType> access(tree);
    auto insertBricks = [&](const GridTopology& topology, const LayerValues& values, bool active) {
        size_t next = 0;
        for (const Brick& b : topology.bricks) {
            auto* leaf = access.touchLeaf(openvdb::Coord(b.x, b.y, b.z));
            const int bx = b.x & 7, by = b.y & 7, bz = b.z & 7;
            for (uint64_t bits = b.mask; bits; bits &= bits - 1) {
                const int i = std::countr_zero(bits);
                const openvdb::Index n = openvdb::Index(((bx + (i & 3)) << 6) | ((by + ((i >> 2) & 3)) << 3) | (bz + (i >> 4)));
                if constexpr (hasValues) {
                    const ValueT v = valueAt<ValueT>(values.bricks, next++);
                    if (active) leaf->setValueOn(n, v);
                    else leaf->setValueOff(n, v);
                } else {
                    leaf->setValueOn(n);
                }
            }
        }
        for (size_t t = 0; t < topology.tiles.size(); ++t) {
            const Tile& tile = topology.tiles[t];
            const auto box = openvdb::CoordBBox::createCube(openvdb::Coord(tile.x, tile.y, tile.z), 1 << tile.log2Size);
            if constexpr (hasValues) tree.sparseFill(box, valueAt<ValueT>(values.tiles, t), active);
            else tree.sparseFill(box, true, true);
        }
    };
    insertBricks(record.topology, record.values, true);
    if constexpr (hasValues) insertBricks(record.inactiveTopology, record.inactiveValues, false);
}

} // namespace

openvdb::GridBase::Ptr buildGrid(const GridRecord& record, const std::string& what) {
    // The descriptor is an empty grid of the original type carrying the
    // name, class, transform, background, half-float flag and metadata.
    openvdb::GridBase::Ptr grid = readDescriptor(record.vdbDescriptor, what);
    if (record.valueType == ValueType::Mask && !grid->isType<openvdb::MaskGrid>()) {
        // Encoded with --topology-only: a MaskGrid with the original header.
        openvdb::MaskGrid::Ptr mask = openvdb::MaskGrid::create();
        for (auto it = grid->beginMeta(); it != grid->endMeta(); ++it) mask->insertMeta(it->first, *it->second);
        mask->setTransform(grid->transform().copy());
        fill(*mask, record);
        return mask;
    }
    const bool supported = dispatchMutableGridType(*grid, [&](auto& typed) { fill(typed, record); });
    if (!supported) throw Error(what + ": grid descriptor has unsupported type '" + grid->type() + "'");
    return grid;
}

} // namespace vdbdag::bridge::detail
