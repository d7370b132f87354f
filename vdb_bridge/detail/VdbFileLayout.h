// The byte layout of a .vdb file up to its grids, checked without OpenVDB:
//   i64 magic 0x56444220 | u32 file version (220-224 read here) |
//   u32 library major | u32 library minor | u8 has-grid-offsets |
//   [u8 compressed, versions 220-221] | 36 ASCII UUID characters |
//   file metadata: u32 count, then per entry string name, string type,
//     u32 size, size bytes (a string is u32 length + bytes) |
//   i32 grid count | per grid: string unique name, string type,
//     string instance parent, then (with offsets) i64 grid, block and end
//     positions; the next grid's descriptor starts at the end position.
// Every size is checked against the file's length before it is used.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace vdbdag::bridge::detail {

struct VdbGridEntry {
    std::string uniqueName, type, instanceParent;
    int64_t gridPos = 0, blockPos = 0, endPos = 0;
};

struct VdbFileLayout {
    uint32_t fileVersion = 0;
    bool hasGridOffsets = false;
    uint64_t metadataEntries = 0;
    std::vector<VdbGridEntry> grids;  // with offsets only; else just the count below
    int32_t gridCount = 0;
};

// Throws vdbdag::Error naming `path` ("truncated: ...", "not a .vdb file",
// "corrupted: ...") for anything OpenVDB would misread.
VdbFileLayout checkVdbFileLayout(const std::string& path);

// The same check of an in-memory metadata block (a MetaMap serialisation).
void checkMetadataBlock(const uint8_t* data, uint64_t size, const std::string& what);

} // namespace vdbdag::bridge::detail
