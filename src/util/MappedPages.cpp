// See MappedPages.h.
#include "src/util/MappedPages.h"

#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <cinttypes>
#include <cstdio>
#include <utility>
#include <vector>

namespace vdbdag {

size_t releaseMappedPages(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return 0;
    FILE* maps = std::fopen("/proc/self/maps", "r");
    if (!maps) return 0;
    std::vector<std::pair<void*, size_t>> ranges;
    char line[4096];
    while (std::fgets(line, sizeof line, maps)) {
        uintptr_t begin = 0, end = 0;
        char perms[8] = {};
        unsigned long long offset = 0, inode = 0;
        unsigned devMajor = 0, devMinor = 0;
        if (std::sscanf(line, "%" SCNxPTR "-%" SCNxPTR " %7s %llx %x:%x %llu", &begin, &end, perms, &offset, &devMajor, &devMinor, &inode) != 7) continue;
        if (inode == 0 || inode != st.st_ino || makedev(devMajor, devMinor) != st.st_dev || perms[1] == 'w') continue;
        ranges.push_back({reinterpret_cast<void*>(begin), size_t(end - begin)});
    }
    std::fclose(maps);
    // Still this process's mapping of the file: nothing here unmaps it
    // between the lookup and the advice (the caller's thread holds the grid).
    for (const auto& [address, length] : ranges) ::madvise(address, length, MADV_DONTNEED);
    return ranges.size();
}

} // namespace vdbdag
