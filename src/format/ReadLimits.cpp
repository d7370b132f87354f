// See ReadLimits.h.
#include "src/format/ReadLimits.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "src/util/Error.h"

namespace vdbdag::format {
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

ReadLimits defaultReadLimits(unsigned valueCopies) {
    ReadLimits l;
    l.maxVoxels = kDefaultMaxVoxels;
    l.maxMemory = defaultReadMemory();
    l.valueCopies = valueCopies;
    return l;
}

std::string describeBytes(uint64_t bytes) {
    const char* units[] = {"bytes", "KB", "MB", "GB", "TB", "PB", "EB"};
    double v = double(bytes);
    int u = 0;
    while (v >= 1000 && u < 6) v /= 1000, ++u;
    char text[48];
    if (u == 0) std::snprintf(text, sizeof text, "%llu bytes", static_cast<unsigned long long>(bytes));
    else std::snprintf(text, sizeof text, "%.3g %s", v, units[u]);
    return text;
}

void checkMemory(const ReadLimits& limits, uint64_t bytes, const std::string& what, const std::string& holding) {
    if (bytes <= limits.maxMemory) return;
    throw Error(what + ": " + holding + " would take at least " + describeBytes(bytes) + " of memory, more than --max-memory " +
                describeBytes(limits.maxMemory) + " (raise it if the file is trusted)");
}

void checkVoxels(const ReadLimits& limits, uint64_t voxels, const std::string& what) {
    if (voxels <= limits.maxVoxels) return;
    throw Error(what + ": decodes to " + std::to_string(voxels) + " voxels (a tile counted once), more than --max-voxels " + std::to_string(limits.maxVoxels) +
                " (raise it if the file is trusted)");
}

} // namespace vdbdag::format
