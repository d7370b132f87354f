// The memory an out-of-core command works within (`--memory-limit`, shared
// by `encode` and `verify`): the default limit, the share of it each
// scratch space keeps in memory, and the cube encoder's budget under it.
#pragma once
#include <cstdint>
#include <string>

#include "src/pipeline/CubeEncoder.h"

namespace vdbdag::app {

// Without --memory-limit: half of the physical memory.
uint64_t defaultMemoryLimit();

// Scratch bytes each scratch space keeps in memory before it writes a file:
// a quarter of what the limit leaves beyond 1 GiB (none under a tight
// limit, where the cubes in flight take it all).
uint64_t scratchInMemory(uint64_t memoryLimit);

// The cube encoder's budget under `memoryLimit` (0: the default), its coded
// values spilled to a scratch file beside `spillNear`.
pipeline::CubeBudget cubeBudget(uint64_t memoryLimit, const std::string& spillNear);

} // namespace vdbdag::app
