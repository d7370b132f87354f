// How much a reader may expand a file: a forged .ssvdag of a few kilobytes
// can claim sections of gigabytes (every one a genuine zstd frame) or a DAG
// whose shared subtrees stand for 2^60 voxels. The reader checks what the
// file's table and DAG imply against these limits before it inflates or
// decodes anything (`--max-voxels`, `--max-memory` on the commands that
// expand a file), and names the limit when a file would exceed it.
#pragma once
#include <cstdint>
#include <limits>
#include <string>

namespace vdbdag::format {

struct ReadLimits {
    // Entries of any one layer of a grid: the values a decode emits one by
    // one (each voxel of a brick; a tile, however large, once).
    uint64_t maxVoxels = std::numeric_limits<uint64_t>::max();
    // Bytes the read may hold: the inflated sections, the decoded values,
    // and `valueCopies` more copies of every voxel's value (the command's
    // own, e.g. the OpenVDB grid a decode builds). A lower bound of what
    // the command will use, so a file within it may still need more.
    uint64_t maxMemory = std::numeric_limits<uint64_t>::max();
    unsigned valueCopies = 0;
};

// Voxels a reader accepts unless told otherwise (`--max-voxels`): 2^36, the
// voxels of a 4096^3 dense block, far past any file of one's own.
inline constexpr uint64_t kDefaultMaxVoxels = uint64_t(1) << 36;

// Memory a reader accepts unless told otherwise (`--max-memory`): three
// quarters of the physical memory, or of what the process's address-space
// (beyond what it maps already), data or cgroup limit leaves when lower.
uint64_t defaultReadMemory();

// Both defaults, for a command that builds `valueCopies` copies of every value.
ReadLimits defaultReadLimits(unsigned valueCopies = 0);

// "1.5 GB"-style figure for messages.
std::string describeBytes(uint64_t bytes);

// Throws Error("<what>: ... more than --max-memory ...") if `bytes` > limits.maxMemory.
void checkMemory(const ReadLimits& limits, uint64_t bytes, const std::string& what, const std::string& holding);
// Throws Error("<what>: ... more than --max-voxels ...") if `voxels` > limits.maxVoxels.
void checkVoxels(const ReadLimits& limits, uint64_t voxels, const std::string& what);

// a + b and a * b, saturating at 2^64 - 1 (figures derived from a forged file).
inline uint64_t saturatingAdd(uint64_t a, uint64_t b) { return a > std::numeric_limits<uint64_t>::max() - b ? std::numeric_limits<uint64_t>::max() : a + b; }
inline uint64_t saturatingMul(uint64_t a, uint64_t b) {
    return b && a > std::numeric_limits<uint64_t>::max() / b ? std::numeric_limits<uint64_t>::max() : a * b;
}

} // namespace vdbdag::format
