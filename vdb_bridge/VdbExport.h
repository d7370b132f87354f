// Writing vdbdag's Volume back to a .vdb file. Until value channels exist,
// each grid is written as a MaskGrid with the original name, class,
// transform and metadata (restored from GridRecord::vdbDescriptor); active
// tiles are written as tiles, never expanded.
#pragma once
#include <string>

#include "src/volume/GridRecord.h"

namespace vdbdag::bridge {

// Writes atomically (temporary name, then rename). Throws vdbdag::Error.
void exportVdb(const Volume& volume, const std::string& path);

} // namespace vdbdag::bridge
