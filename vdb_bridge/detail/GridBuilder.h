// Private: rebuilds the OpenVDB grid of a decoded GridRecord: the original
// type, name, class, transform, background and metadata (from the
// descriptor), active voxels and tiles with their values, and the inactive
// values that differ from the background. Tiles stay tiles. Used by the
// exporter and by the comparison behind `verify`.
#pragma once
#include <openvdb/openvdb.h>

#include "src/volume/GridRecord.h"

namespace vdbdag::bridge::detail {

openvdb::GridBase::Ptr buildGrid(const GridRecord& record, const std::string& what);

} // namespace vdbdag::bridge::detail
