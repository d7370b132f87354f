// See VdbFile.h.
#include "vdb_bridge/detail/VdbFile.h"

#include <fstream>
#include <sstream>

#include <openvdb/io/Archive.h>
#include <openvdb/io/File.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/io/Stream.h>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFileLayout.h"

namespace vdbdag::bridge::detail {
namespace {

// OpenVDB's archive writer, given a stream of ours: io::File writes through
// an std::ofstream whose failures it never checks.
class StreamArchive : public openvdb::io::Archive {
public:
    void writeTo(std::ostream& out, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& metadata) const {
        Archive::write(out, grids, /*seekable=*/true, metadata);
    }
};

// Runs `read`, turning OpenVDB's exceptions into one vdbdag::Error naming
// `path` (our own Errors and std::bad_alloc pass through).
template <typename Read>
auto reportingReadErrors(const std::string& path, Read&& read) {
    try {
        return read();
    } catch (const Error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path + ": cannot be read as a .vdb file (" + oneLine(e.what()) + ")");
    }
}

} // namespace

VdbFileContents readVdbFile(const std::string& path) {
    initializeOpenVdb();
    const VdbFileLayout layout = checkVdbFileLayout(path);
    VdbFileContents contents;
    contents.fileVersion = layout.fileVersion;
    reportingReadErrors(path, [&] {
        if (layout.hasGridOffsets) {
            // io::File without delayed loading is OpenVDB's strictest reader
            // (it checks every compressed block's size); grids are read one
            // by one by their unique names, in file order.
            openvdb::io::File file(path);
            file.open(/*delayLoad=*/false);
            contents.metadata = file.getMetadata();
            for (const VdbGridEntry& entry : layout.grids)
                contents.grids.push_back(file.readGrid(openvdb::io::GridDescriptor::nameAsString(entry.uniqueName)));
            file.close();
        } else {
            // A stream (no offsets): read in order, whole.
            std::ifstream in(path, std::ios::binary);
            if (!in) throw Error(path + ": cannot be opened");
            openvdb::io::Stream stream(in, /*delayLoad=*/false);
            contents.metadata = stream.getMetadata();
            openvdb::GridPtrVecPtr grids = stream.getGrids();
            if (!grids || in.fail()) throw Error(path + ": truncated or corrupted (the file ends inside its grids)");
            contents.grids = *grids;
        }
    });
    if (!contents.metadata) contents.metadata = std::make_shared<openvdb::MetaMap>();
    if (contents.grids.size() != size_t(layout.gridCount))
        throw Error(path + ": corrupted: the file lists " + std::to_string(layout.gridCount) + " grids but " + std::to_string(contents.grids.size()) +
                    " could be read");
    for (size_t i = 0; i < contents.grids.size(); ++i) {
        if (!contents.grids[i]) throw Error(path + ": grid " + std::to_string(i) + " could not be read");
        checkGridAgainstFile(path, i, *contents.grids[i]);
    }
    return contents;
}

void checkGridAgainstFile(const std::string& path, size_t index, const openvdb::GridBase& g) {
    // OpenVDB reads a file cut short without complaint (missing nodes are
    // simply absent); its writer's own voxel count gives it away.
    const std::string which = path + ": grid " + std::to_string(index) + " '" + g.getName() + "'";
    if (!g.baseTreePtr()) throw Error(which + " could not be read");
    // A transform OpenVDB reads but cannot use (a zero scale, a singular
    // matrix) throws later from wherever it is first used, without a name.
    try {
        (void)g.transform().baseMap()->getAffineMap();
    } catch (const std::exception& e) {
        throw Error(which + " has an unusable transform (" + oneLine(e.what()) + ")");
    }
    const uint64_t voxels = g.activeVoxelCount();
    if (const auto count = g.getMetadata<openvdb::Int64Metadata>(openvdb::GridBase::META_FILE_VOXEL_COUNT))
        if (uint64_t(count->value()) != voxels)
            throw Error(which + " is truncated or corrupted: it reads as " + std::to_string(voxels) + " active voxels but the file says " +
                        std::to_string(count->value()));
    // The writer's bounding box too: OpenVDB recomputes it on every write,
    // so a corrupted one could not come back.
    const auto lo = g.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
    const auto hi = g.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
    if (voxels > 0 && lo && hi) {
        const openvdb::CoordBBox box = g.evalActiveVoxelBoundingBox();
        if (openvdb::Vec3i(box.min().asVec3i()) != lo->value() || openvdb::Vec3i(box.max().asVec3i()) != hi->value())
            throw Error(which + " is corrupted: its active voxels span " + openvdb::Vec3IMetadata(box.min().asVec3i()).str() + ".." +
                        openvdb::Vec3IMetadata(box.max().asVec3i()).str() + " but the file says " + lo->str() + ".." + hi->str());
    }
}

VdbFileIndex indexVdbFile(const std::string& path) {
    initializeOpenVdb();
    const VdbFileLayout layout = checkVdbFileLayout(path);
    if (!layout.hasGridOffsets) throw Error(path + ": an OpenVDB stream without grid offsets cannot be read region by region");
    VdbFileIndex index;
    reportingReadErrors(path, [&] {
        openvdb::io::File file(path);
        file.setCopyMaxBytes(0);  // never a private copy in the temporary directory
        file.open(/*delayLoad=*/true);
        index.metadata = file.getMetadata();
        file.close();
    });
    if (!index.metadata) index.metadata = std::make_shared<openvdb::MetaMap>();
    for (const VdbGridEntry& entry : layout.grids) index.uniqueNames.push_back(openvdb::io::GridDescriptor::nameAsString(entry.uniqueName));
    return index;
}

openvdb::GridBase::Ptr readGridDelayed(const std::string& path, const std::string& uniqueName) {
    initializeOpenVdb();
    return reportingReadErrors(path, [&] {
        openvdb::io::File file(path);
        file.setCopyMaxBytes(0);
        file.open(/*delayLoad=*/true);
        openvdb::GridBase::Ptr grid = file.readGrid(uniqueName);
        file.close();  // the leaves keep the file mapped
        if (!grid) throw Error(path + ": grid '" + uniqueName + "' could not be read");
        return grid;
    });
}

void writeVdbFile(const std::string& path, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& metadata) {
    initializeOpenVdb();
    writeStreamAtomically(path, [&](std::ostream& out) {
        try {
            StreamArchive().writeTo(out, grids, metadata);
        } catch (const openvdb::Exception& e) {
            throw Error(path + ": OpenVDB could not write the file (" + oneLine(e.what()) + ")");
        }
    });
}

std::vector<uint8_t> serializeMetadata(const openvdb::MetaMap& metadata) {
    if (metadata.metaCount() == 0) return {};
    std::ostringstream out(std::ios::binary);
    metadata.writeMeta(out);
    const std::string s = out.str();
    return std::vector<uint8_t>(s.begin(), s.end());
}

openvdb::MetaMap::Ptr parseMetadata(const std::vector<uint8_t>& bytes, const std::string& what) {
    initializeOpenVdb();
    auto meta = std::make_shared<openvdb::MetaMap>();
    if (bytes.empty()) return meta;
    checkMetadataBlock(bytes.data(), bytes.size(), what + ": file metadata");
    try {
        std::istringstream in(std::string(bytes.begin(), bytes.end()), std::ios::binary);
        meta->readMeta(in);
        if (in.fail()) throw Error(what + ": file metadata is corrupted");
    } catch (const openvdb::Exception& e) {
        throw Error(what + ": file metadata is corrupted (" + oneLine(e.what()) + ")");
    }
    return meta;
}

} // namespace vdbdag::bridge::detail
