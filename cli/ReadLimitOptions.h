// `--max-voxels N` and `--max-memory SIZE` for the commands that expand a
// .ssvdag (decode, export, info, render, verify, diff) or import a scan: what a file from elsewhere may
// make vdbdag hold before it is refused (format/ReadLimits.h).
#pragma once
#include <cstdint>

#include <CLI/CLI.hpp>

#include "src/format/ReadLimits.h"

namespace vdbdag::cli {

struct ReadLimitOptions {
    uint64_t maxVoxels = format::kDefaultMaxVoxels;
    uint64_t maxMemory = 0;  // 0: format::defaultReadMemory()
    void add(CLI::App& cmd);
    // The limits for a command that builds `valueCopies` copies of every voxel's value.
    format::ReadLimits limits(unsigned valueCopies) const;
};

} // namespace vdbdag::cli
