// Writing vdbdag's Volume back to a .vdb file: each grid with its original
// type, name, class, transform, background and metadata (restored from
// GridRecord::vdbDescriptor), its active values and its stored inactive
// values; active tiles are written as tiles, never expanded.
#pragma once
#include <functional>
#include <string>

#include "src/volume/GridRecord.h"

namespace vdbdag::bridge {

// Writes atomically (temporary name, then rename). Throws vdbdag::Error.
// `onStep(done, total)`: called as each grid is built and once more when the
// file is written (total = grids + 1), for progress.
void exportVdb(const Volume& volume, const std::string& path, const std::function<void(size_t done, size_t total)>& onStep = {});

} // namespace vdbdag::bridge
