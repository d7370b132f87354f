// Records the largest single allocation made while a probe is alive, so a
// test can prove a forged size was refused before it was allocated (the
// test binary's operator new, AllocationProbe.cpp, does the recording).
#pragma once
#include <atomic>
#include <cstddef>

namespace vdbdag::test {

extern std::atomic<bool> gTrackAllocations;
extern std::atomic<size_t> gLargestAllocation;

struct AllocationProbe {
    AllocationProbe() {
        gLargestAllocation = 0;
        gTrackAllocations = true;
    }
    ~AllocationProbe() { gTrackAllocations = false; }
    AllocationProbe(const AllocationProbe&) = delete;
    AllocationProbe& operator=(const AllocationProbe&) = delete;
    size_t largest() const { return gLargestAllocation.load(); }
};

} // namespace vdbdag::test
