// See ReadLimitOptions.h.
#include "cli/ReadLimitOptions.h"

#include "cli/ByteSize.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>

namespace vdbdag::cli {
namespace {

uint64_t cgroupLimit() {
    std::ifstream in("/sys/fs/cgroup/memory.max");
    std::string text;
    if (!(in >> text) || text == "max") return UINT64_MAX;
    try {
        return std::stoull(text);
    } catch (...) {
        return UINT64_MAX;
    }
}

// Address space the process already uses (its libraries, thread stacks):
// an address-space limit leaves only the rest.
uint64_t addressSpaceInUse() {
    std::ifstream in("/proc/self/statm");
    uint64_t pages = 0;
    if (!(in >> pages)) return 0;
    const long size = sysconf(_SC_PAGE_SIZE);
    return pages * uint64_t(size > 0 ? size : 4096);
}

} // namespace

uint64_t defaultReadMemory() {
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    uint64_t available = pages > 0 && size > 0 ? uint64_t(pages) * uint64_t(size) : uint64_t(8) << 30;
    for (const int resource : {RLIMIT_AS, RLIMIT_DATA}) {
        rlimit r{};
        if (getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) continue;
        const uint64_t inUse = resource == RLIMIT_AS ? addressSpaceInUse() : 0;
        available = std::min<uint64_t>(available, r.rlim_cur > inUse ? r.rlim_cur - inUse : 0);
    }
    available = std::min(available, cgroupLimit());
    return available / 4 * 3;
}

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
    l.maxMemory = maxMemory ? maxMemory : defaultReadMemory();
    l.valueCopies = valueCopies;
    return l;
}

} // namespace vdbdag::cli
