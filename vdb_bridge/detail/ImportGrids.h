// OpenVDB grids already in memory -> Volume, as importVdb does for a .vdb
// file's grids (VdbImport.h): shared with the NanoVDB reader (NanoVdb.h),
// whose grids NanoVDB converts to OpenVDB's first. `path` names the file in
// messages.
#pragma once
#include <string>

#include <openvdb/openvdb.h>

#include "vdb_bridge/VdbImport.h"

namespace vdbdag::bridge::detail {

ImportResult importGrids(const openvdb::GridPtrVec& grids, const openvdb::MetaMap& metadata, const std::string& path, const ImportOptions& options);

// `--normals`: whether `grid` gets normals (scalar: its gradient; vec3: it
// is the --normal-grid), refusing a --normal-grid that names a grid of
// another type; and, after every grid, refusing a file none of whose
// grids got normals. The whole-file and region-by-region readers share them.
enum class NormalsOf { None, Gradient, Vectors };
NormalsOf normalsOf(const openvdb::GridBase& grid, const ImportOptions& options, const std::string& path);
void requireSomeNormals(bool found, const ImportOptions& options, const std::string& path);

} // namespace vdbdag::bridge::detail
