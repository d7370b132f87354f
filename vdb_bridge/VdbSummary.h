// The header facts `vdb_print -l -m` prints, for `info`: the tree type,
// voxel size, grid and file metadata, read from a GridRecord's descriptor
// and a Volume's file metadata (so from a .ssvdag too); and for a .vdb the
// bounding box, value range and tile count as OpenVDB itself computes them
// (evalActiveVoxelBoundingBox, tools::minMax, activeTileCount), the
// reference that format::summarizeGrid (GridSummary.h) must agree with.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "src/format/GridSummary.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::bridge {

struct MetadataEntry {
    std::string name, type, value;  // value as OpenVDB's Metadata::str()
};

struct GridHeaderFacts {
    std::string treeType;               // "Tree_float_5_4_3"
    std::array<double, 3> voxelSize{};  // Transform::voxelSize()
    std::string transform;              // the map's type ("UniformScaleMap", ...)
    std::vector<MetadataEntry> metadata;  // sorted by name, as OpenVDB's MetaMap iterates
    // The index box through the transform (Transform::indexToWorld of a
    // CoordBBox: the box of its eight corners); absent without a box.
    std::optional<std::array<double, 6>> worldBox;  // min x y z, max x y z
};
// From a record's descriptor (throws vdbdag::Error naming `what`).
GridHeaderFacts gridHeaderFacts(const GridRecord& record, const std::optional<format::IndexBox>& indexBox, const std::string& what);
std::vector<MetadataEntry> fileMetadataEntries(const std::vector<uint8_t>& fileMetadata, const std::string& what);

// Every grid of a .vdb file, whole, as OpenVDB computes it.
struct VdbGridFacts {
    GridRecord header;  // name, class, value type, transform matrix, descriptor, background; no voxels
    GridHeaderFacts facts;
    format::GridSummary summary;  // solidNodes = OpenVDB's active tile count
};
struct VdbFileFacts {
    std::vector<VdbGridFacts> grids;
    std::vector<MetadataEntry> fileMetadata;
    uint32_t fileVersion = 0;  // the header's file format version (222, 223, 224, ...), as vdb_print -l shows
};
VdbFileFacts vdbFileFacts(const std::string& path);

} // namespace vdbdag::bridge
