// Private: builds the OpenVDB MaskGrid of a decoded GridRecord (topology with
// tiles kept as tiles, header restored from the descriptor). Used by the
// exporter and by the comparison, which checks it against the original file.
#pragma once
#include <openvdb/openvdb.h>

#include "src/volume/GridRecord.h"

namespace vdbdag::bridge::detail {

openvdb::MaskGrid::Ptr buildMaskGrid(const GridRecord& record, const std::string& what);

} // namespace vdbdag::bridge::detail
