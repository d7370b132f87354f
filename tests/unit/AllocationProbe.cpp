// The test binary's operator new: see AllocationProbe.h.
#include "tests/unit/AllocationProbe.h"

#include <cstdlib>
#include <new>

namespace vdbdag::test {
std::atomic<bool> gTrackAllocations{false};
std::atomic<size_t> gLargestAllocation{0};
} // namespace vdbdag::test

void* operator new(size_t n) {
    using namespace vdbdag::test;
    if (gTrackAllocations.load(std::memory_order_relaxed)) {
        size_t prev = gLargestAllocation.load(std::memory_order_relaxed);
        while (n > prev && !gLargestAllocation.compare_exchange_weak(prev, n)) {
        }
    }
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void* operator new[](size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
void operator delete[](void* p, size_t) noexcept { std::free(p); }
