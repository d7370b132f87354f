// Synthetic grids for the selftest and the brute-force reference they are
// compared against. A SyntheticGrid is a plain list of voxels (and tiles)
// with raw value bytes; toRecord() groups the voxels into the 4^3 bricks a
// GridRecord holds (input order: per brick, increasing bit order). The
// reference, flatten(), walks every set bit of every brick one by one into a
// coordinate -> bytes map: it shares no code with the DAG builder, the
// attribute order or the palette channel, so a round trip compared through
// it is checked independently. Values compare as raw bytes (bit-exact: NaN
// payloads, -0.0, denormals).
#pragma once
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "src/volume/GridRecord.h"

namespace vdbdag::selftest {

struct SyntheticGrid {
    ValueType type = ValueType::Float;
    std::vector<std::array<int32_t, 3>> voxels;  // distinct coordinates
    std::vector<uint8_t> voxelValues;            // valueSize(type) bytes per voxel
    std::vector<Tile> tiles;                     // disjoint from the voxels
    std::vector<uint8_t> tileValues;             // valueSize(type) bytes per tile

    void addVoxel(int32_t x, int32_t y, int32_t z, const void* value);
    void addTile(const Tile& tile, const void* value);
};

// The grid as a GridRecord (class "unknown", background all-zero bytes).
GridRecord toRecord(const SyntheticGrid& grid, const std::string& name);

// Every active voxel with its value bytes, by a walk over every brick bit;
// tiles up to kExpandTileLog2 wide count as their voxels (a decoder may
// store a uniform node either way), larger tiles are kept as tiles.
inline constexpr unsigned kExpandTileLog2 = 5;
struct FlatGrid {
    std::map<std::array<int64_t, 3>, std::string> voxels;
    std::map<std::array<int64_t, 4>, std::string> tiles;  // x, y, z, log2Size
};
FlatGrid flatten(const GridRecord& record);

// "" when identical, else the first difference in words ("voxel (1,2,3):
// 0x7fc00001 became 0x7fc00000", "voxel (...) missing", ...).
std::string firstDifference(const FlatGrid& want, const FlatGrid& got);

// Value bytes as hex, lowest address first per value ("0x" + bytes as a
// little-endian integer for 4- and 8-byte values).
std::string hexValue(const std::string& bytes);

} // namespace vdbdag::selftest
