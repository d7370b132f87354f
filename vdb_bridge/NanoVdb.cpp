// See NanoVdb.h.
#include "vdb_bridge/NanoVdb.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <type_traits>

#include <iostream>  // nanovdb/util/GridValidator.h uses std::cerr without including it

#include <nanovdb/util/GridValidator.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/NanoToOpenVDB.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/InputPath.h"
#include "src/util/OutputPath.h"
#include "vdb_bridge/detail/GridBuilder.h"
#include "vdb_bridge/detail/ImportGrids.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge {

using detail::oneLine;

bool isNanoVdbPath(const std::string& path) { return lowerExtension(path) == ".nvdb"; }

namespace {

// NanoVDB trusts the offsets in a grid's buffer: nanoToOpenVDB walks them
// as pointers, so a damaged file crashed inside it. Before the walk, each
// grid goes through NanoVDB's own validator (nanovdb/util/GridValidator.h:
// magic, version, the full checksum where the file carries one, grid type
// and class, every node pointer inside the buffer and 32-byte aligned), and
// its name must end inside its 256 bytes. "" when the grid passes (or is of
// a type nanoToOpenVDB does not convert, which the caller reports).
// Every child pointer of the tree (root tiles, upper and lower internal
// nodes) must point at a node of the level below, inside the buffer: the
// nodes of a level lie back to back where the tree's node offsets say, so a
// child is the start of one of them. NanoVDB's validator checks the first
// node of each level only; a flipped child offset or child-mask bit crashed
// nanoToOpenVDB.
template <typename T>
std::string checkChildPointers(const nanovdb::NanoGrid<T>& grid, uint64_t bufferSize) {
    using TreeT = nanovdb::NanoTree<T>;
    const auto* base = reinterpret_cast<const uint8_t*>(&grid);
    const TreeT& tree = grid.tree();
    const auto* treeBytes = reinterpret_cast<const uint8_t*>(&tree);
    const auto* data = tree.data();
    // Level L's nodes: [begin, begin + count * size), inside the buffer.
    const auto level = [&](int l, uint64_t count, uint64_t size, const uint8_t*& begin) -> bool {
        const uint64_t offset = data->mNodeOffset[l];
        const uint64_t treeAt = uint64_t(treeBytes - base);
        if (count == 0) return begin = nullptr, true;
        if (offset > bufferSize - treeAt || count > (bufferSize - treeAt - offset) / size) return false;
        begin = treeBytes + offset;
        return true;
    };
    using UpperT = nanovdb::NanoUpper<T>;
    using LowerT = nanovdb::NanoLower<T>;
    using LeafT = nanovdb::NanoLeaf<T>;
    const uint64_t leaves = data->mNodeCount[0], lowers = data->mNodeCount[1], uppers = data->mNodeCount[2];
    const uint8_t *leafBegin, *lowerBegin, *upperBegin;
    if (!level(0, leaves, sizeof(LeafT), leafBegin) || !level(1, lowers, sizeof(LowerT), lowerBegin) || !level(2, uppers, sizeof(UpperT), upperBegin))
        return "its node counts and offsets run past its buffer";
    const auto isNode = [](const void* p, const uint8_t* begin, uint64_t count, uint64_t size) {
        const auto* b = static_cast<const uint8_t*>(p);
        return begin && b >= begin && uint64_t(b - begin) < count * size && uint64_t(b - begin) % size == 0;
    };
    const auto& root = tree.root();
    const auto* rootBytes = reinterpret_cast<const uint8_t*>(&root);
    if (rootBytes < base || uint64_t(rootBytes - base) + sizeof(root) > bufferSize) return "its root lies outside its buffer";
    const uint64_t tiles = root.data()->mTableSize;
    using TileT = typename nanovdb::NanoRoot<T>::DataType::Tile;
    if (tiles > (bufferSize - uint64_t(rootBytes - base) - sizeof(root)) / sizeof(TileT)) return "its root's tile table runs past its buffer";
    for (uint32_t i = 0; i < tiles; ++i) {
        const auto* tile = root.data()->tile(i);
        if (tile->isChild() && !isNode(root.data()->getChild(tile), upperBegin, uppers, sizeof(UpperT))) return "a root child pointer points at no upper node";
    }
    for (uint64_t k = 0; k < uppers; ++k) {
        const auto* node = reinterpret_cast<const UpperT*>(upperBegin + k * sizeof(UpperT));
        for (auto it = node->data()->mChildMask.beginOn(); it; ++it)
            if (!isNode(node->data()->getChild(*it), lowerBegin, lowers, sizeof(LowerT))) return "an upper node's child pointer points at no lower node";
    }
    // FpN leaves vary in size (each its own bit width): a child is then any
    // 32-byte aligned place from the first leaf on where a leaf header fits.
    const auto isLeaf = [&](const void* p) {
        if constexpr (std::is_same_v<T, nanovdb::FpN>) {
            const auto* b = static_cast<const uint8_t*>(p);
            return leafBegin && b >= leafBegin && uint64_t(b - base) + sizeof(LeafT) <= bufferSize && uint64_t(b - base) % NANOVDB_DATA_ALIGNMENT == 0;
        } else {
            return isNode(p, leafBegin, leaves, sizeof(LeafT));
        }
    };
    for (uint64_t k = 0; k < lowers; ++k) {
        const auto* node = reinterpret_cast<const LowerT*>(lowerBegin + k * sizeof(LowerT));
        for (auto it = node->data()->mChildMask.beginOn(); it; ++it)
            if (!isLeaf(node->data()->getChild(*it))) return "a lower node's child pointer points at no leaf";
    }
    return "";
}

template <typename T>
std::string validateAs(const nanovdb::NanoGrid<T>& grid, uint64_t bufferSize) {
    if (std::string bad = nanovdb::GridValidator<T>::check(grid, /*detailed*/ true); !bad.empty()) return bad;
    return checkChildPointers(grid, bufferSize);
}

std::string validateGrid(const nanovdb::GridHandle<nanovdb::HostBuffer>& handle) {
    const nanovdb::GridData* data = reinterpret_cast<const nanovdb::GridData*>(handle.data());
    if (!data || handle.size() < sizeof(nanovdb::GridData)) return "its grid holds fewer bytes than a grid header";
    if (data->mGridSize > handle.size()) return "its grid declares more bytes than it holds";
    if (!std::memchr(data->mGridName, 0, nanovdb::GridData::MaxNameSize)) return "its grid name does not end";
    if (auto g = handle.grid<float>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<double>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<int32_t>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<int64_t>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<bool>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<nanovdb::Fp4>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<nanovdb::Fp8>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<nanovdb::Fp16>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<nanovdb::FpN>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<nanovdb::ValueMask>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<nanovdb::Vec3f>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<nanovdb::Vec3d>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<nanovdb::Vec4f>()) return validateAs(*g, handle.size());
    if (auto g = handle.grid<nanovdb::Vec4d>()) return validateAs(*g, handle.size());
    return "";
}

} // namespace

ImportResult importNanoVdb(const std::string& path, const ImportOptions& options) {
    checkInputFile(path, "a NanoVDB file");
    detail::initializeOpenVdb();
    const uint64_t fileBytes = std::filesystem::file_size(path);
    // The grids' declared sizes first: NanoVDB allocates what a header
    // claims, so a claim the file cannot hold is refused before that.
    std::vector<nanovdb::io::GridMetaData> metas;
    try {
        metas = nanovdb::io::readGridMetaData(path);
    } catch (const std::exception& e) {
        throw Error(path + ": not a NanoVDB file, or a damaged one (" + oneLine(e.what()) + ")");
    }
    // A compressed grid (blosc or zip) may claim at most 1032 times its stored
    // bytes: zlib's largest ratio, above what blosc reaches on real grids.
    for (size_t i = 0; i < metas.size(); ++i) {
        const auto& m = metas[i];
        const bool raw = m.codec == nanovdb::io::Codec::NONE;
        if (m.fileSize > fileBytes || (raw && m.gridSize != m.fileSize) || m.gridSize / 1032 > std::max<uint64_t>(m.fileSize, 1))
            throw Error(path + ": grid " + std::to_string(i) + " declares " + std::to_string(m.gridSize) + " bytes in " + std::to_string(m.fileSize) +
                        " stored (the file holds " + std::to_string(fileBytes) + "): the file is damaged");
    }
    openvdb::GridPtrVec grids;
    try {
        const auto handles = nanovdb::io::readGrids(path);
        for (size_t i = 0; i < handles.size(); ++i) {
            if (const std::string bad = validateGrid(handles[i]); !bad.empty())
                throw Error(path + ": grid " + std::to_string(i) + " is damaged (" + bad + ")");
            const nanovdb::GridMetaData* meta = handles[i].gridMetaData();
            try {
                grids.push_back(nanovdb::nanoToOpenVDB(handles[i]));
            } catch (const std::exception&) {
                const std::string name = meta ? meta->shortGridName() : "";
                const std::string type = meta ? nanovdb::toStr(meta->gridType()) : "unknown";
                const std::string message = "grid " + std::to_string(i) + " '" + name + "' has NanoVDB type '" + type + "', which vdbdag does not convert";
                if (!options.skipUnsupported) throw Error(path + ": " + message + " (use --skip-unsupported to convert the other grids)");
            }
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path + ": NanoVDB could not read the file (" + oneLine(e.what()) + ")");
    }
    ImportResult result = detail::importGrids(grids, openvdb::MetaMap(), path, options);
    if (grids.size() < metas.size())
        result.warnings.push_back(path + ": skipped " + std::to_string(metas.size() - grids.size()) + " grid(s) of a NanoVDB type vdbdag does not convert");
    return result;
}

void exportNanoVdb(const Volume& volume, const std::string& path, const std::function<void(size_t done, size_t total)>& onStep) {
    detail::initializeOpenVdb();
    std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
    const size_t steps = volume.grids.size() + 1;
    for (size_t g = 0; g < volume.grids.size(); ++g) {
        const GridRecord& record = volume.grids[g];
        const std::string what = path + ": grid " + std::to_string(g) + " '" + record.name + "'";
        if (record.valueType == ValueType::Vec3I) throw Error(what + ": NanoVDB has no vec3i grids (write a .vdb instead)");
        const openvdb::GridBase::Ptr grid = detail::buildGrid(record, what);
        try {
            handles.push_back(nanovdb::openToNanoVDB(grid));
        } catch (const std::exception& e) {
            throw Error(what + ": NanoVDB could not convert it (" + oneLine(e.what()) + ")");
        }
        if (onStep) onStep(g + 1, steps);
    }
    writeStreamAtomically(path, [&](std::ostream& out) {
        try {
            nanovdb::io::writeGrids(out, handles);
        } catch (const std::exception& e) {
            throw Error(path + ": NanoVDB could not write the file (" + oneLine(e.what()) + ")");
        }
    });
    if (onStep) onStep(steps, steps);
}

} // namespace vdbdag::bridge
