// See MaskGridBuilder.h.
#include "vdb_bridge/detail/MaskGridBuilder.h"

#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge::detail {

openvdb::MaskGrid::Ptr buildMaskGrid(const GridRecord& record, const std::string& what) {
    const openvdb::GridBase::Ptr header = readDescriptor(record.vdbDescriptor, what);
    openvdb::MaskGrid::Ptr grid = openvdb::MaskGrid::create();
    // All of the original's metadata, which holds its name and class when it
    // has them (an unnamed grid has no "name" entry, and must not gain one).
    for (auto it = header->beginMeta(); it != header->endMeta(); ++it) grid->insertMeta(it->first, *it->second);
    grid->setTransform(header->transform().copy());

    openvdb::MaskTree& tree = grid->tree();
    openvdb::tree::ValueAccessor<openvdb::MaskTree> access(tree);
    for (const Brick& b : record.topology.bricks) {
        auto* leaf = access.touchLeaf(openvdb::Coord(b.x, b.y, b.z));
        const int bx = b.x & 7, by = b.y & 7, bz = b.z & 7;
        for (uint64_t bits = b.mask; bits; bits &= bits - 1) {
            const int i = std::countr_zero(bits);
            const int x = bx + (i & 3), y = by + ((i >> 2) & 3), z = bz + (i >> 4);
            leaf->setValueOn(openvdb::Index((x << 6) | (y << 3) | z));
        }
    }
    for (const Tile& t : record.topology.tiles) {
        tree.sparseFill(openvdb::CoordBBox::createCube(openvdb::Coord(t.x, t.y, t.z), 1 << t.log2Size), true, true);
    }
    return grid;
}

} // namespace vdbdag::bridge::detail
