// The grids of a .vdb file as CubeSources (src/volume/CubeSource.h): read
// region by region through OpenVDB's delayed loading, so the out-of-core
// encoder never holds a whole grid. Each pass opens the file afresh (a
// delayed-loading grid keeps every leaf it has loaded), and every leaf is
// dropped from the tree as soon as the last cube that needs it is read.
// A file without grid offsets (an OpenVDB stream) cannot be loaded lazily:
// openVdbCubes refuses it and callers read it whole (importVdb).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "src/volume/CubeSource.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::bridge {

struct VdbCubeInput {
    std::vector<uint8_t> fileMetadata;  // Volume::fileMetadata
    std::vector<std::unique_ptr<CubeSource>> grids;  // file order
    std::vector<std::string> warnings;
};

// Whether `path` can be read cube by cube (a .vdb with grid offsets).
bool canReadVdbByCubes(const std::string& path);

// The file is checked like importVdb (layout, voxel counts, bounding
// boxes) and each grid is summarised (one pass over its leaves) before
// this returns. `options.normals` is not supported (Error).
VdbCubeInput openVdbCubes(const std::string& path, const ImportOptions& options = {});

} // namespace vdbdag::bridge
