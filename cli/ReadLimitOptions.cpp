// See ReadLimitOptions.h.
#include "cli/ReadLimitOptions.h"

#include "cli/ByteSize.h"

namespace vdbdag::cli {
void ReadLimitOptions::add(CLI::App& cmd) {
    cmd.add_option("--max-voxels", maxVoxels, "refuse a grid that decodes to more voxels than this, a tile counted once (a forged file may claim any number)")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd.add_option("--max-memory", maxMemory,
                   "refuse a file whose sections and decoded values would take more memory than this, e.g. 2G "
                   "(default: three quarters of the physical memory or of the process's memory limit)")
        ->transform(byteSize());
}

format::ReadLimits ReadLimitOptions::limits(unsigned valueCopies) const {
    format::ReadLimits l;
    l.maxVoxels = maxVoxels;
    l.maxMemory = maxMemory ? maxMemory : format::defaultReadMemory();
    l.valueCopies = valueCopies;
    return l;
}

} // namespace vdbdag::cli
