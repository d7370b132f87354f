// .vdb -> Volume: grid headers (with OpenVDB's own serialisation of an empty
// copy of each grid as the descriptor) and active topology as 4^3 bricks plus
// active tiles, which are never expanded into voxels.
#include "vdb_bridge/VdbImport.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include <openvdb/openvdb.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/parallel_for.h>

#include "src/util/Error.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge {
namespace {

// Splits every leaf's 8^3 value mask into its (non-empty) 4^3 bricks. Leaves
// are visited in the tree's order, so the output order is deterministic.
template <typename TreeT>
void collectBricks(const TreeT& tree, std::vector<Brick>& bricks) {
    std::vector<const typename TreeT::LeafNodeType*> leaves;
    leaves.reserve(tree.leafCount());
    for (auto it = tree.cbeginLeaf(); it; ++it) leaves.push_back(it.getLeaf());
    std::vector<std::array<Brick, 8>> perLeaf(leaves.size());
    std::vector<uint8_t> count(leaves.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 256), [&](const auto& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) {
            const auto& leaf = *leaves[i];
            const openvdb::Coord origin = leaf.origin();
            // OpenVDB leaf words: 8 x uint64, word w holds x = w, bits (y<<3 | z).
            const auto& mask = leaf.getValueMask();
            uint64_t words[8];
            for (int w = 0; w < 8; ++w) words[w] = mask.template getWord<openvdb::Index64>(w);
            uint64_t brick[8] = {0, 0, 0, 0, 0, 0, 0, 0};
            for (int x = 0; x < 8; ++x) {
                const uint64_t word = words[x];
                if (!word) continue;
                for (int yz = 0; yz < 64; ++yz) {
                    if (!((word >> yz) & 1u)) continue;
                    const int y = yz >> 3, z = yz & 7;
                    const int b = (x >> 2) | ((y >> 2) << 1) | ((z >> 2) << 2);
                    brick[b] |= uint64_t(1) << brickBitIndex(x & 3, y & 3, z & 3);
                }
            }
            uint8_t n = 0;
            for (int b = 0; b < 8; ++b)
                if (brick[b])
                    perLeaf[i][n++] = Brick{origin.x() + ((b & 1) ? 4 : 0), origin.y() + ((b & 2) ? 4 : 0), origin.z() + ((b & 4) ? 4 : 0), brick[b]};
            count[i] = n;
        }
    });
    for (size_t i = 0; i < leaves.size(); ++i) bricks.insert(bricks.end(), perLeaf[i].begin(), perLeaf[i].begin() + count[i]);
}

template <typename GridT>
GridTopology topologyOf(const GridT& grid) {
    GridTopology topology;
    const auto& tree = grid.tree();
    collectBricks(tree, topology.bricks);
    // Active tiles at every level above the leaves (voxels are not visited).
    typename GridT::TreeType::ValueOnCIter it = tree.cbeginValueOn();
    it.setMaxDepth(GridT::TreeType::ValueOnCIter::LEAF_DEPTH - 1);
    for (; it; ++it) {
        if (!it.isTileValue()) continue;
        const openvdb::CoordBBox box = it.getBoundingBox();
        const int size = box.dim().x();
        topology.tiles.push_back({box.min().x(), box.min().y(), box.min().z(), uint8_t(std::countr_zero(unsigned(size)))});
    }
    return topology;
}

std::vector<uint8_t> descriptorOf(const openvdb::GridBase& grid) {
    openvdb::GridBase::Ptr empty = grid.copyGridWithNewTree();
    std::ostringstream out(std::ios::binary);
    openvdb::io::Stream stream(out);
    stream.setGridStatsMetadataEnabled(false);
    stream.write(openvdb::GridCPtrVec{empty});
    std::string s = out.str();
    // The stream header carries a random UUID (36 ASCII characters after the
    // 8-byte magic, u32 file version, 2 x u32 library version and a flag
    // byte). Fix it so the same input always gives a byte-identical file.
    constexpr size_t kUuidOffset = 21, kUuidLength = 36;
    if (s.size() < kUuidOffset + kUuidLength || s[kUuidOffset + 8] != '-')
        throw Error("internal error: unexpected OpenVDB stream header layout");
    s.replace(kUuidOffset, kUuidLength, "00000000-0000-0000-0000-000000000000");
    return std::vector<uint8_t>(s.begin(), s.end());
}

std::array<double, 16> indexToWorldOf(const openvdb::GridBase& grid) {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const auto map = grid.transform().baseMap();
    if (map && map->isLinear()) {
        const openvdb::Mat4d mat = map->getAffineMap()->getMat4();
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) m[size_t(4 * r + c)] = mat(r, c);
    }
    return m;
}

} // namespace

ImportResult importVdb(const std::string& path, const ImportOptions& options) {
    detail::initializeOpenVdb();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw Error(path + ": no such file");
    if (std::filesystem::is_directory(path, ec)) throw Error(path + ": is a directory, not a .vdb file");
    openvdb::GridPtrVecPtr grids;
    try {
        // Delayed loading: topology (node masks) is read now, leaf value
        // buffers only when touched, so a geometry-only import never
        // decompresses the values.
        openvdb::io::File file(path);
        file.open(true);
        grids = file.getGrids();
        file.close();
    } catch (const openvdb::Exception& e) {
        throw Error(path + ": cannot be read as a .vdb file (" + detail::oneLine(e.what()) + ")");
    } catch (const std::exception& e) {
        throw Error(path + ": cannot be read as a .vdb file (" + detail::oneLine(e.what()) + ")");
    }

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
    for (size_t index = 0; index < grids->size(); ++index) {
        const openvdb::GridBase::Ptr& base = (*grids)[index];
        if (!options.onlyGrids.empty() &&
            std::find(options.onlyGrids.begin(), options.onlyGrids.end(), base->getName()) == options.onlyGrids.end())
            continue;
        GridRecord record;
        record.name = base->getName();
        record.gridClass = openvdb::GridBase::gridClassToString(base->getGridClass());
        const bool supported = detail::dispatchGridType(*base, [&](const auto& grid, ValueType type) {
            record.valueType = type;
            record.topology = topologyOf(grid);
        });
        if (!supported) {
            const std::string message = "grid " + std::to_string(index) + " '" + base->getName() + "' has type '" + base->type() + "'" +
                                        detail::typeHint(*base) + ", which vdbdag does not convert";
            if (!options.skipUnsupported) throw Error(path + ": " + message + " (use --skip-unsupported to convert the other grids)");
            result.warnings.push_back(path + ": skipped " + message);
            continue;
        }
        record.indexToWorld = indexToWorldOf(*base);
        record.vdbDescriptor = descriptorOf(*base);
        result.volume.grids.push_back(std::move(record));
    }
    return result;
}

} // namespace vdbdag::bridge
