// See MemoryBudget.h.
#include "app/MemoryBudget.h"

#include <unistd.h>

#include <algorithm>

namespace vdbdag::app {

uint64_t defaultMemoryLimit() {
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? uint64_t(pages) * uint64_t(size) / 2 : uint64_t(4) << 30;
}

uint64_t scratchInMemory(uint64_t memoryLimit) {
    constexpr uint64_t kReserved = uint64_t(1) << 30;
    return memoryLimit > kReserved ? (memoryLimit - kReserved) / 4 : 0;
}

pipeline::CubeBudget cubeBudget(uint64_t memoryLimit, const std::string& spillNear) {
    const uint64_t limit = memoryLimit ? memoryLimit : defaultMemoryLimit();
    pipeline::CubeBudget budget;
    budget.bytes = std::max<uint64_t>(limit / 2, 1);
    budget.spillInMemory = scratchInMemory(limit);
    budget.spillNear = spillNear;  // the coded values wait in a scratch file, not in memory, until the file is written
    return budget;
}

} // namespace vdbdag::app
