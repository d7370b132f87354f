// `--max-voxels N` and `--max-memory SIZE` for the commands that expand a
// .ssvdag (decode, export, info, render): what a file from elsewhere may
// make vdbdag hold before it is refused (format/ReadLimits.h).
#pragma once
#include <cstdint>

#include <CLI/CLI.hpp>

#include "src/format/ReadLimits.h"

namespace vdbdag::cli {

struct ReadLimitOptions {
    uint64_t maxVoxels = uint64_t(1) << 36;
    uint64_t maxMemory = 0;  // 0: defaultReadMemory()
    void add(CLI::App& cmd);
    // The limits for a command that builds `valueCopies` copies of every voxel's value.
    format::ReadLimits limits(unsigned valueCopies) const;
};

// Without --max-memory: three quarters of the physical memory, or of what
// the process's address-space (beyond what it maps already), data or
// cgroup limit leaves when that is lower.
uint64_t defaultReadMemory();

} // namespace vdbdag::cli
