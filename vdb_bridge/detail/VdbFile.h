// The one place vdbdag reads and writes .vdb files with OpenVDB.
//
// Reading: the file's structure (header, file metadata, grid descriptors and
// their offsets) is checked here first (VdbFileLayout.h), because OpenVDB
// accepts a file cut short as fewer or empty grids and asserts on some
// corruptions; then the grids are read in file order (io::File returns them
// sorted by name) as one stream, whole, so a truncation inside a grid shows
// up as a failed stream, and each grid's active voxel count is checked
// against the count OpenVDB's writer recorded.
//
// Writing: OpenVDB's archive writes into a stream whose every write is
// checked (AtomicFile.h's writeStreamAtomically), so a full disk is an error
// and never a corrupt file; io::File would drop the error.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>

namespace vdbdag::bridge::detail {

struct VdbFileContents {
    openvdb::MetaMap::Ptr metadata;  // file-level metadata (never null)
    openvdb::GridPtrVec grids;       // in file order
    uint32_t fileVersion = 0;        // the header's file format version (222, 223, 224, ...)
};

// Throws vdbdag::Error naming `path` for a missing, short, corrupt or
// unreadable file.
VdbFileContents readVdbFile(const std::string& path);

// For the cube-by-cube reader (VdbCubes.h): the file checked like
// readVdbFile, its metadata and its grids' unique names in file order; then
// one grid at a time with OpenVDB's delayed loading (leaf buffers are read
// from the file when first touched). Throws for a file without offsets.
struct VdbFileIndex {
    openvdb::MetaMap::Ptr metadata;
    std::vector<std::string> uniqueNames;  // file order
};
VdbFileIndex indexVdbFile(const std::string& path);
openvdb::GridBase::Ptr readGridDelayed(const std::string& path, const std::string& uniqueName);
// readVdbFile's checks of grid `index` against what the writer recorded.
void checkGridAgainstFile(const std::string& path, size_t index, const openvdb::GridBase& grid);

// Writes `grids` (in this order) and the file metadata atomically.
void writeVdbFile(const std::string& path, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& metadata);

// File-level metadata as bytes (OpenVDB's own MetaMap serialisation), the
// form a Volume carries it in, and back. Empty bytes: no metadata.
std::vector<uint8_t> serializeMetadata(const openvdb::MetaMap& metadata);
openvdb::MetaMap::Ptr parseMetadata(const std::vector<uint8_t>& bytes, const std::string& what);

} // namespace vdbdag::bridge::detail
