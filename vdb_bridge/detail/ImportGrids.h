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

} // namespace vdbdag::bridge::detail
