// Private: the grids of a .vdb or .ssvdag file as OpenVDB grids, for the VTK
// exporters and the diff. A .vdb is read by OpenVDB itself; an .ssvdag is
// read, validated and decoded (pipeline::decodeScene), then rebuilt with its
// original types, transforms and tiles (GridBuilder). Chosen by extension.
#pragma once
#include <string>
#include <vector>

#include <openvdb/openvdb.h>

#include "src/format/ReadLimits.h"

namespace vdbdag::bridge::detail {

struct LoadedGrid {
    size_t fileIndex = 0;  // position in the file
    openvdb::GridBase::Ptr grid;
};

bool isSsvdagPath(const std::string& path);

// All grids, or those named in `onlyGrids` (an unknown name is an error that
// lists the names the file has). Grids of types vdbdag does not convert are
// an error naming the grid and its type. Throws vdbdag::Error("PATH: ...").
// An .ssvdag is read within `limits` (format/ReadLimits.h).
std::vector<LoadedGrid> loadGrids(const std::string& path, const std::vector<std::string>& onlyGrids, const format::ReadLimits& limits = {});

// "'name'" or "#index" for unnamed grids, for messages and block names.
std::string gridLabel(const LoadedGrid& grid);

} // namespace vdbdag::bridge::detail
