// The grids of a .vdb file as CubeSources (src/volume/CubeSource.h), so the
// out-of-core encoder never holds a whole grid. One pass through OpenVDB's
// delayed loading, a chunk of leaves at a time (each chunk dropped once
// read), writes every leaf's bricks of both layers to a scratch file
// (ScratchFile.h); the encoder's passes then read each cube's bricks back
// from there, with no OpenVDB and no decompression.
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
// boxes) and each grid is read once into the scratch file, created beside
// `scratchNear` (a path in the folder to use; default: the system's
// temporary folder), before this returns. The scratch
// files go with the sources. With `options.normals` a grid's normals are a
// source of their own (CubeSource::normals), computed cube by cube from the
// scratch file with a one-voxel halo, the same as importVdb's; not with
// `options.topologyOnly` (Error: the gradient needs the values).
VdbCubeInput openVdbCubes(const std::string& path, const ImportOptions& options = {}, const std::string& scratchNear = "", uint64_t scratchInMemory = 0);

} // namespace vdbdag::bridge
