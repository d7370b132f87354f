// The test binary's allocation recording: see AllocationProbe.h. In a plain
// build, operator new is replaced; under AddressSanitizer (scripts/
// sanitize.sh), whose own operator new must stay (it pairs every new with
// its delete), the sanitizer's allocation hook records instead.
#include "tests/unit/AllocationProbe.h"

#include <cstdlib>
#include <new>

#if defined(__SANITIZE_ADDRESS__)
#define VDBDAG_PROBE_BY_SANITIZER_HOOK 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VDBDAG_PROBE_BY_SANITIZER_HOOK 1
#endif
#endif

namespace vdbdag::test {
std::atomic<bool> gTrackAllocations{false};
std::atomic<size_t> gLargestAllocation{0};

namespace {
void record(size_t n) {
    if (!gTrackAllocations.load(std::memory_order_relaxed)) return;
    size_t prev = gLargestAllocation.load(std::memory_order_relaxed);
    while (n > prev && !gLargestAllocation.compare_exchange_weak(prev, n)) {
    }
}
} // namespace
} // namespace vdbdag::test

#ifdef VDBDAG_PROBE_BY_SANITIZER_HOOK
// From the sanitizer runtime (sanitizer/allocator_interface.h, which GCC does not install).
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*, size_t), void (*free_hook)(const volatile void*));

namespace {
void onMalloc(const volatile void*, size_t n) { vdbdag::test::record(n); }
void onFree(const volatile void*) {}
const int kInstalled = __sanitizer_install_malloc_and_free_hooks(onMalloc, onFree);
} // namespace
#else
void* operator new(size_t n) {
    vdbdag::test::record(n);
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void* operator new[](size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, size_t) noexcept { std::free(p); }
void operator delete[](void* p, size_t) noexcept { std::free(p); }
#endif
