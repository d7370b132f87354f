// Volumes to VTK XML for ParaView (`vdbdag export`): a sparse grid becomes a
// .vtu of its active voxels (one world-space cell per voxel, one cell per
// active tile, never expanded) with one cell-data array per grid; a dense
// grid or a --bbox region becomes a .vti (a cell per voxel, origin, spacing
// and direction from the grid's linear transform, plus an `active` array);
// several grids become a .vtm multiblock. A .ssvdag input is decoded first.
// Size limits stop accidental densification or huge meshes before anything
// is built or written.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "src/format/ReadLimits.h"

namespace vdbdag::bridge {

struct VtkExportOptions {
    std::vector<std::string> grids;                 // empty: every grid
    std::optional<std::array<int32_t, 6>> bbox;     // inclusive index-space box X0,Y0,Z0,X1,Y1,Z1
    uint64_t maxCells = 20'000'000;                 // per unstructured block
    uint64_t maxImageBytes = uint64_t(256) << 20;    // per image block (values + active flags)
    std::string compressor = "zlib";                // or "lz4"
    format::ReadLimits limits;                      // for an .ssvdag input
};

struct VtkBlockReport {
    std::string grid;        // name as in the file
    size_t fileIndex = 0;
    std::string valueType;   // OpenVDB's type name
    std::string kind;        // "unstructured" or "image"
    uint64_t cells = 0;
    uint64_t tileCells = 0;  // unstructured: cells that are whole tiles
    std::array<int64_t, 6> region{};  // image: inclusive index box
};

struct VtkExportReport {
    std::vector<VtkBlockReport> blocks;
    uint64_t bytes = 0;  // of the written file(s)
};

// Output type by extension: .vtu, .vti or .vtm. Throws vdbdag::Error.
VtkExportReport exportVtk(const std::string& input, const std::string& output, const VtkExportOptions& options);

} // namespace vdbdag::bridge
