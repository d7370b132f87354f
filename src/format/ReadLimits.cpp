// See ReadLimits.h.
#include "src/format/ReadLimits.h"

#include <cstdio>

#include "src/util/Error.h"

namespace vdbdag::format {

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
