// Inputs several tests share: the shared data's .vdb files, and a voxel set
// grouped into 4^3 bricks by a plain walk (independent of the importers).
#pragma once
#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "tests/unit/BuildPaths.h"
#include "src/volume/GridTopology.h"

namespace vdbdag::testing {

// ../shared/data's vdb/ and levelsets/ files but points.vdb (a PointDataGrid),
// sorted; empty when the data is absent.
inline std::vector<std::filesystem::path> sharedVdbFiles() {
    namespace fs = std::filesystem;
    std::vector<fs::path> files;
    for (const char* sub : {"vdb", "levelsets"}) {
        const fs::path dir = fs::path(VDBDAG_SHARED_DATA) / sub;
        if (!fs::is_directory(dir)) continue;
        for (const auto& e : fs::directory_iterator(dir))
            if (e.path().extension() == ".vdb" && e.path().filename() != "points.vdb") files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

using Voxel = std::tuple<int64_t, int64_t, int64_t>;

inline GridTopology topologyFromVoxels(const std::set<Voxel>& voxels) {
    std::map<Voxel, uint64_t> bricks;
    auto floor4 = [](int64_t v) { return v >= 0 ? v / 4 * 4 : -((-v + 3) / 4) * 4; };
    for (const auto& [x, y, z] : voxels) {
        const int64_t bx = floor4(x), by = floor4(y), bz = floor4(z);
        bricks[{bx, by, bz}] |= uint64_t(1) << brickBitIndex(int(x - bx), int(y - by), int(z - bz));
    }
    GridTopology topo;
    for (const auto& [c, mask] : bricks) topo.bricks.push_back({int32_t(std::get<0>(c)), int32_t(std::get<1>(c)), int32_t(std::get<2>(c)), mask});
    return topo;
}

} // namespace vdbdag::testing
