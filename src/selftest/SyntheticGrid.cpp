// See SyntheticGrid.h.
#include "src/selftest/SyntheticGrid.h"

#include <cstring>

#include <fmt/core.h>

#include "src/util/Error.h"

namespace vdbdag::selftest {

void SyntheticGrid::addVoxel(int32_t x, int32_t y, int32_t z, const void* value) {
    voxels.push_back({x, y, z});
    const auto* p = static_cast<const uint8_t*>(value);
    voxelValues.insert(voxelValues.end(), p, p + valueSize(type));
}

void SyntheticGrid::addTile(const Tile& tile, const void* value) {
    tiles.push_back(tile);
    const auto* p = static_cast<const uint8_t*>(value);
    tileValues.insert(tileValues.end(), p, p + valueSize(type));
}

GridRecord toRecord(const SyntheticGrid& grid, const std::string& name) {
    const unsigned vs = valueSize(grid.type);
    if (grid.voxelValues.size() != grid.voxels.size() * vs || grid.tileValues.size() != grid.tiles.size() * vs)
        throw Error("synthetic grid '" + name + "': value count does not match the voxels");
    GridRecord record;
    record.name = name;
    record.gridClass = "unknown";
    record.valueType = grid.type;
    record.background.assign(vs, 0);
    // Brick corner -> (mask, value of each set bit by bit index).
    struct BrickValues {
        uint64_t mask = 0;
        std::array<const uint8_t*, 64> value{};
    };
    std::map<std::array<int32_t, 3>, BrickValues> bricks;
    for (size_t i = 0; i < grid.voxels.size(); ++i) {
        const auto& v = grid.voxels[i];
        const std::array<int32_t, 3> corner{v[0] & ~3, v[1] & ~3, v[2] & ~3};
        const int bit = brickBitIndex(v[0] & 3, v[1] & 3, v[2] & 3);
        BrickValues& b = bricks[corner];
        if (b.mask >> bit & 1) throw Error(fmt::format("synthetic grid '{}': voxel ({},{},{}) given twice", name, v[0], v[1], v[2]));
        b.mask |= uint64_t(1) << bit;
        b.value[bit] = vs ? &grid.voxelValues[i * vs] : nullptr;
    }
    for (const auto& [corner, b] : bricks) {
        record.topology.bricks.push_back({corner[0], corner[1], corner[2], b.mask});
        for (int bit = 0; bit < 64; ++bit)
            if (vs && (b.mask >> bit & 1)) record.values.bricks.insert(record.values.bricks.end(), b.value[bit], b.value[bit] + vs);
    }
    record.topology.tiles = grid.tiles;
    record.values.tiles = grid.tileValues;
    return record;
}

FlatGrid flatten(const GridRecord& record) {
    FlatGrid flat;
    const unsigned vs = valueSize(record.valueType);
    size_t next = 0;
    for (const Brick& b : record.topology.bricks)
        for (int z = 0; z < 4; ++z)
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 4; ++x) {
                    if (!(b.mask >> brickBitIndex(x, y, z) & 1)) continue;
                    // The value order is "increasing bit order", which for bit = x + 4y + 16z is this z, y, x loop.
                    std::string value;
                    if (vs) {
                        if ((next + 1) * vs > record.values.bricks.size()) throw Error("grid '" + record.name + "': fewer brick values than voxels");
                        value.assign(reinterpret_cast<const char*>(&record.values.bricks[next * vs]), vs);
                    }
                    ++next;
                    const std::array<int64_t, 3> c{int64_t(b.x) + x, int64_t(b.y) + y, int64_t(b.z) + z};
                    if (!flat.voxels.emplace(c, value).second)
                        throw Error(fmt::format("grid '{}': voxel ({},{},{}) in two bricks", record.name, c[0], c[1], c[2]));
                }
    if (next * vs != record.values.bricks.size()) throw Error("grid '" + record.name + "': more brick values than voxels");
    if (record.values.tiles.size() != record.topology.tiles.size() * vs) throw Error("grid '" + record.name + "': tile value count mismatch");
    for (size_t i = 0; i < record.topology.tiles.size(); ++i) {
        const Tile& t = record.topology.tiles[i];
        const std::string value = vs ? std::string(reinterpret_cast<const char*>(&record.values.tiles[i * vs]), vs) : std::string();
        if (t.log2Size > kExpandTileLog2) {
            flat.tiles[{t.x, t.y, t.z, t.log2Size}] = value;
            continue;
        }
        const int64_t n = int64_t(1) << t.log2Size;
        for (int64_t z = 0; z < n; ++z)
            for (int64_t y = 0; y < n; ++y)
                for (int64_t x = 0; x < n; ++x)
                    if (!flat.voxels.emplace(std::array<int64_t, 3>{t.x + x, t.y + y, t.z + z}, value).second)
                        throw Error(fmt::format("grid '{}': tile at ({},{},{}) overlaps a voxel", record.name, t.x, t.y, t.z));
    }
    return flat;
}

std::string hexValue(const std::string& bytes) {
    if (bytes.empty()) return "(no value)";
    std::string out = "0x";
    if (bytes.size() == 4 || bytes.size() == 8) {  // little-endian integer, as the bit pattern is usually written
        for (size_t i = bytes.size(); i-- > 0;) out += fmt::format("{:02x}", uint8_t(bytes[i]));
        return out;
    }
    for (char c : bytes) out += fmt::format("{:02x}", uint8_t(c));
    return out;
}

std::string firstDifference(const FlatGrid& want, const FlatGrid& got) {
    auto where = [](const std::array<int64_t, 3>& c) { return fmt::format("({},{},{})", c[0], c[1], c[2]); };
    for (const auto& [c, value] : want.voxels) {
        const auto it = got.voxels.find(c);
        if (it == got.voxels.end()) return "voxel " + where(c) + " missing after the round trip";
        if (it->second != value) return "voxel " + where(c) + ": " + hexValue(value) + " became " + hexValue(it->second);
    }
    for (const auto& [c, value] : got.voxels)
        if (!want.voxels.count(c)) return "voxel " + where(c) + " appeared in the round trip";
    for (const auto& [t, value] : want.tiles) {
        const auto it = got.tiles.find(t);
        const std::string name = fmt::format("tile ({},{},{}) 2^{}", t[0], t[1], t[2], t[3]);
        if (it == got.tiles.end()) return name + " missing (or expanded) after the round trip";
        if (it->second != value) return name + ": " + hexValue(value) + " became " + hexValue(it->second);
    }
    for (const auto& [t, value] : got.tiles)
        if (!want.tiles.count(t)) return fmt::format("tile ({},{},{}) 2^{} appeared in the round trip", t[0], t[1], t[2], t[3]);
    return {};
}

} // namespace vdbdag::selftest
