// The `geometry` group (issue 7 part 2): extreme topologies through the
// whole file round trip, each compared voxel by voxel (and value by value:
// every voxel carries a distinct float, so an attribute-order slip under
// symmetry shows) with the brute-force reference of SyntheticGrid.h, both
// as an SSVDAG and as a plain SVDAG. Empty
// grid; one voxel; one voxel at each corner of the int32 cube; coordinates
// spanning the whole int32 range; a voxel checkerboard and random noise,
// where the DAG must never hold more nodes than the sparse voxel octree it
// replaces, at any level (factor 1: merging only removes nodes; the
// checkerboard is periodic and collapses to a node or two per level, the
// noise has almost no sharing); a 4096^3 active tile, which must stay one
// tile with one value (never expanded: 2 attribute entries for 2^36 + 1
// voxels, and a file at most 128 bytes larger than the same grid without
// the tile).
#include <cstring>
#include <limits>
#include <random>
#include <set>

#include <fmt/core.h>

#include "src/selftest/CaseGroups.h"
#include "src/selftest/FileRoundTrip.h"
#include "src/selftest/SyntheticGrid.h"

namespace vdbdag::selftest {
namespace {

constexpr int32_t kMin = std::numeric_limits<int32_t>::min(), kMax = std::numeric_limits<int32_t>::max();

// A distinct, non-trivial float per voxel (hash of the coordinate).
float valueAt(int64_t x, int64_t y, int64_t z) {
    uint64_t h = uint64_t(x) * 0x9E3779B97F4A7C15ull ^ uint64_t(y) * 0xC2B2AE3D27D4EB4Full ^ uint64_t(z) * 0x165667B19E3779F9ull;
    h ^= h >> 29;
    return float(int32_t(h & 0xFFFFFF) - 0x800000) * 0.125f;
}

void addVoxel(SyntheticGrid& grid, int32_t x, int32_t y, int32_t z) {
    const float v = valueAt(x, y, z);
    grid.addVoxel(x, y, z, &v);
}

// Round trip + exact comparison, through the SSVDAG (kept in `rt` for the
// figures) and through the plain SVDAG (--no-symmetry), both required exact.
struct Exact {
    FileRoundTrip rt;
    Checks checks;
    size_t voxels = 0;
};
Exact exactRoundTrip(const SyntheticGrid& grid, const std::string& name) {
    Exact out;
    const GridRecord record = toRecord(grid, name);
    const FlatGrid want = flatten(record);
    out.voxels = want.voxels.size();
    pipeline::EncodeOptions plain;
    plain.symmetry = false;
    const std::string plainDiff = firstDifference(want, flatten(roundTripThroughFile(record, plain).decoded));
    out.checks.require(plainDiff.empty(), "plain SVDAG: " + plainDiff);
    out.rt = roundTripThroughFile(record);
    const std::string diff = firstDifference(want, flatten(out.rt.decoded));
    out.checks.require(diff.empty(), "SSVDAG: " + diff);
    return out;
}

// Stored nodes <= SVO nodes at every level; returns the total ratio.
double checkNodeFactor(Exact& e, double factor) {
    const auto& s = e.rt.stored.stats;
    e.checks.require(!s.svoNodes.empty() && s.svoNodes.size() == s.storedNodes.size(), "no per-level node statistics");
    for (size_t i = 0; i < s.storedNodes.size() && i < s.svoNodes.size(); ++i)
        e.checks.require(double(s.storedNodes[i]) <= factor * double(s.svoNodes[i]),
                         fmt::format("level 2^{}: {} DAG nodes > {} x {} SVO nodes", i + 2, s.storedNodes[i], factor, s.svoNodes[i]));
    return double(storedNodeCount(s)) / double(std::max<uint64_t>(1, svoNodeCount(s)));
}

void addCases(std::vector<SelftestCase>& cases) {
    cases.push_back({"geometry", "empty-grid", "empty after decode", "an empty grid decodes to an empty grid (no nodes, no values)", [] {
                         SyntheticGrid grid;
                         Exact e = exactRoundTrip(grid, "empty");
                         e.checks.require(e.rt.decoded.topology.empty() && e.rt.stored.active.dag.empty(), "the decoded grid is not empty");
                         e.checks.require(e.rt.traceable.entryCount == 0, "the empty grid stores values");
                         return e.checks.result(fmt::format("{} voxels", e.rt.decoded.topology.activeVoxelCount()), fmt::format("0 voxels, DAG {} bytes, file {} bytes", e.rt.dagBytes(), e.rt.fileBytes));
                     }});

    cases.push_back({"geometry", "one-voxel", "exact", "one voxel at (5,-7,3): exact voxel and value", [] {
                         SyntheticGrid grid;
                         addVoxel(grid, 5, -7, 3);
                         Exact e = exactRoundTrip(grid, "one voxel");
                         return e.checks.result(e.checks.passed() ? "1 voxel exact" : "differs", fmt::format("{} voxel, root 2^{}, DAG {} bytes, file {} bytes", e.voxels, e.rt.stored.active.dag.log2Size,
                                                            e.rt.dagBytes(), e.rt.fileBytes));
                     }});

    cases.push_back({"geometry", "int32-corners", "exact", "one voxel at each of the 8 corners of the int32 cube, one grid each: exact voxel and value", [] {
                         Checks checks;
                         unsigned maxRoot = 0, exact = 0;
                         uint64_t maxFile = 0;
                         for (int corner = 0; corner < 8; ++corner) {
                             SyntheticGrid grid;
                             addVoxel(grid, corner & 1 ? kMax : kMin, corner & 2 ? kMax : kMin, corner & 4 ? kMax : kMin);
                             Exact e = exactRoundTrip(grid, fmt::format("corner {}", corner));
                             exact += checks.require(e.checks.passed(), e.checks.result("", fmt::format("corner {}", corner)).measured);
                             maxRoot = std::max<unsigned>(maxRoot, e.rt.stored.active.dag.log2Size);
                             maxFile = std::max(maxFile, e.rt.fileBytes);
                         }
                         return checks.result(fmt::format("{}/8 exact", exact), fmt::format("{} of 8 corners exact; largest root 2^{}, largest file {} bytes", exact, maxRoot, maxFile));
                     }});

    cases.push_back({"geometry", "int32-span", "exact",
                     "the 8 int32 corners, the origin, 2000 random voxels over the whole int32 range and tiles of 8^3 and 128^3, "
                     "one grid: every voxel and value exact, tiles kept",
                     [] {
                         SyntheticGrid grid;
                         const Tile small{kMax - 4095, kMin + 4096, 8, 3}, large{kMax - 255, kMin + 128, -1024, 7};
                         auto inTile = [](const Tile& t, int64_t x, int64_t y, int64_t z) {
                             const int64_t n = int64_t(1) << t.log2Size;
                             return x >= t.x && x < t.x + n && y >= t.y && y < t.y + n && z >= t.z && z < t.z + n;
                         };
                         std::set<std::array<int32_t, 3>> used;
                         auto add = [&](int32_t x, int32_t y, int32_t z) {
                             if (inTile(small, x, y, z) || inTile(large, x, y, z) || !used.insert({x, y, z}).second) return;
                             addVoxel(grid, x, y, z);
                         };
                         for (int corner = 0; corner < 8; ++corner) add(corner & 1 ? kMax : kMin, corner & 2 ? kMax : kMin, corner & 4 ? kMax : kMin);
                         add(0, 0, 0);
                         add(-1, -1, -1);
                         std::mt19937_64 rng(5);
                         for (int i = 0; i < 2000; ++i) add(int32_t(uint32_t(rng())), int32_t(uint32_t(rng())), int32_t(uint32_t(rng())));
                         const float a = 1.5f, b = -2.25f;
                         grid.addTile(small, &a);
                         grid.addTile(large, &b);
                         Exact e = exactRoundTrip(grid, "int32 span");
                         return e.checks.result(fmt::format("{} voxels + 1 tile exact", e.voxels), fmt::format("{} voxels (tiles counted as voxels up to 32^3) + 1 large tile exact, root 2^{}, "
                                                            "origin ({},{},{}), file {} bytes",
                                                            e.voxels, e.rt.stored.active.dag.log2Size, e.rt.stored.active.dag.origin[0], e.rt.stored.active.dag.origin[1],
                                                            e.rt.stored.active.dag.origin[2], e.rt.fileBytes));
                     }});

    static constexpr double kFactor = 1.0;
    cases.push_back({"geometry", "checkerboard", fmt::format("nodes <= {} x SVO", kFactor),
                     fmt::format("64^3 voxel checkerboard (x+y+z even), distinct values: exact; DAG nodes <= {} x SVO nodes at every level", kFactor),
                     [] {
                         SyntheticGrid grid;
                         for (int z = 0; z < 64; ++z)
                             for (int y = 0; y < 64; ++y)
                                 for (int x = 0; x < 64; ++x)
                                     if ((x + y + z) % 2 == 0) addVoxel(grid, x - 32, y + 7, z - 1000);
                         Exact e = exactRoundTrip(grid, "checkerboard");
                         const double ratio = checkNodeFactor(e, kFactor);
                         return e.checks.result(fmt::format("x {:.4f}", ratio), fmt::format("{} voxels; DAG {} nodes vs SVO {} (factor {:.4f}); DAG {} bytes ({:.3f} bits/voxel)",
                                                            e.voxels, storedNodeCount(e.rt.stored.stats), svoNodeCount(e.rt.stored.stats), ratio,
                                                            e.rt.dagBytes(), 8.0 * double(e.rt.dagBytes()) / double(e.voxels)));
                     }});

    cases.push_back({"geometry", "random-noise", fmt::format("nodes <= {} x SVO", kFactor),
                     fmt::format("48^3 box, each voxel active with p = 1/2, distinct values: exact; DAG nodes <= {} x SVO nodes at every level", kFactor),
                     [] {
                         SyntheticGrid grid;
                         std::mt19937_64 rng(6);
                         for (int z = 0; z < 48; ++z)
                             for (int y = 0; y < 48; ++y)
                                 for (int x = 0; x < 48; ++x)
                                     if (rng() & 1) addVoxel(grid, x + 13, y - 21, z + 2);
                         Exact e = exactRoundTrip(grid, "noise");
                         const double ratio = checkNodeFactor(e, kFactor);
                         const auto& s = e.rt.stored.stats;
                         return e.checks.result(fmt::format("x {:.4f}", ratio), fmt::format("{} voxels; DAG {} nodes vs SVO {} (factor {:.4f}; bricks {} vs {}); DAG {} bytes "
                                                            "({:.3f} bits per voxel of the box)",
                                                            e.voxels, storedNodeCount(s), svoNodeCount(s), ratio, s.storedNodes.at(0), s.svoNodes.at(0),
                                                            e.rt.dagBytes(), 8.0 * double(e.rt.dagBytes()) / (48.0 * 48 * 48)));
                     }});

    // The tile's cost is measured against a baseline in the same run: the
    // same grid without the tile (one voxel).
    static constexpr uint64_t kTileExtraBytes = 128;
    cases.push_back({"geometry", "active-tile-4096", fmt::format("<= 1 voxel + {} B", kTileExtraBytes),
                     fmt::format("a 4096^3 active tile + one voxel: exact, the tile stays one tile (2 attribute entries for 2^36 + 1 voxels), "
                                 "file <= the one-voxel grid's file + {} bytes",
                                 kTileExtraBytes),
                     [] {
                         SyntheticGrid grid;
                         addVoxel(grid, 5, -7, 3);
                         const uint64_t baseline = exactRoundTrip(grid, "tile").rt.fileBytes;
                         const float tileValue = 0.25f;
                         grid.addTile({-4096, 0, 4096, 12}, &tileValue);
                         Exact e = exactRoundTrip(grid, "tile");
                         const GridTopology& t = e.rt.decoded.topology;
                         e.checks.require(t.tiles.size() == 1 && t.tiles[0].log2Size == 12 && t.bricks.size() == 1,
                                          fmt::format("decoded as {} tiles and {} bricks", t.tiles.size(), t.bricks.size()));
                         e.checks.require(e.rt.traceable.entryCount == 2, fmt::format("{} attribute entries", e.rt.traceable.entryCount));
                         e.checks.require(e.rt.stored.active.voxels == (uint64_t(1) << 36) + 1, fmt::format("{} active voxels", e.rt.stored.active.voxels));
                         e.checks.require(e.rt.fileBytes <= baseline + kTileExtraBytes, fmt::format("file {} bytes, one voxel alone {}", e.rt.fileBytes, baseline));
                         return e.checks.result(fmt::format("+{} B, {} tile", int64_t(e.rt.fileBytes) - int64_t(baseline), t.tiles.size()),
                                                fmt::format("{} active voxels in {} attribute entries; file {} bytes (one voxel alone: {}), DAG {} bytes "
                                                            "over {} levels, root 2^{}",
                                                            e.rt.stored.active.voxels, e.rt.traceable.entryCount, e.rt.fileBytes, baseline,
                                                            e.rt.dagBytes(), e.rt.stored.active.dag.log2Size - 1, e.rt.stored.active.dag.log2Size));
                     }});
}

} // namespace

void addGeometryCases(std::vector<SelftestCase>& cases) { addCases(cases); }

} // namespace vdbdag::selftest
