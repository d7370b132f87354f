// Two sets of OpenVDB grids compared with OpenVDB's own API, for tests whose
// reference is a .vdb: names, value types, backgrounds, topologies, active
// voxel counts, transforms, and every value (active and inactive, voxels
// and tiles) bit for bit. Metadata is not compared (NanoVDB keeps none).
#pragma once
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <type_traits>

#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>

namespace vdbdag::testing {

struct SameTree {
    const openvdb::GridBase& other;
    std::string& why;
    template <typename GridT>
    void operator()(const GridT& a) const {
        const auto* bp = dynamic_cast<const GridT*>(&other);
        if (!bp) { why = "value types differ (" + a.type() + " vs " + other.type() + ")"; return; }
        const GridT& b = *bp;
        using V = typename GridT::ValueType;
        auto same = [](const V& x, const V& y) {
            if constexpr (std::is_same_v<V, bool> || std::is_same_v<V, openvdb::ValueMask>) return x == y;
            else return std::memcmp(&x, &y, sizeof(V)) == 0;
        };
        if (!same(a.background(), b.background())) { why = "backgrounds differ"; return; }
        if (!a.tree().hasSameTopology(b.tree())) { why = "topologies differ"; return; }
        if (a.activeVoxelCount() != b.activeVoxelCount()) { why = "active voxel counts differ"; return; }
        if (a.transform() != b.transform()) { why = "transforms differ"; return; }
        // Every value of every leaf (active and inactive) and every tile.
        auto acc = b.getConstAccessor();
        for (auto it = a.tree().cbeginValueAll(); it; ++it) {
            const openvdb::Coord c = it.getCoord();
            if (!same(*it, acc.getValue(c)) || it.isValueOn() != acc.isValueOn(c)) {
                why = "the value at (" + std::to_string(c.x()) + "," + std::to_string(c.y()) + "," + std::to_string(c.z()) + ") differs";
                return;
            }
        }
    }
};

// "" when `a` and `b` hold the same grids (names, order, trees), else why not.
inline std::string sameGrids(const openvdb::GridPtrVec& a, const openvdb::GridPtrVec& b) {
    if (a.size() != b.size()) return std::to_string(a.size()) + " grids vs " + std::to_string(b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        if (a[i]->getName() != b[i]->getName()) return "grid " + std::to_string(i) + ": names differ";
        std::string why;
        if (!a[i]->apply<openvdb::GridTypes>(SameTree{*b[i], why})) return "grid " + std::to_string(i) + ": type not compared";
        if (!why.empty()) return "grid " + std::to_string(i) + " '" + a[i]->getName() + "': " + why;
    }
    return "";
}

inline openvdb::GridPtrVec readVdb(const std::filesystem::path& path) {
    openvdb::io::File f(path.string());
    f.open(false);
    openvdb::GridPtrVec grids = *f.getGrids();
    // io::File lists grids by name; the .nvdb keeps the file order: compare by name.
    std::sort(grids.begin(), grids.end(), [](const auto& x, const auto& y) { return x->getName() < y->getName(); });
    return grids;
}

} // namespace vdbdag::testing
