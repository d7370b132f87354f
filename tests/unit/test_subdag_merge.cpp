// The split build (SubDagMerge.h, SSVDAG paper §4.2) against the in-core
// build: for every cube size, the merged DAG must be the in-core DAG, node
// for node and number for number (so the file is byte-identical whatever
// the memory limit), and must decode to the input voxels (brute force).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "src/dag/DagBuilder.h"
#include "tests/unit/TestInputs.h"
#include "src/dag/SubDagMerge.h"
#include "src/encoding/CompactDag.h"
#include "src/util/Error.h"

using namespace vdbdag;

namespace {

using vdbdag::testing::Voxel;
using vdbdag::testing::topologyFromVoxels;

// A voxel set of a topology, bricks expanded, tiles kept as (corner, size).
std::set<std::tuple<int64_t, int64_t, int64_t, int>> cellsOf(const GridTopology& topo) {
    std::set<std::tuple<int64_t, int64_t, int64_t, int>> cells;
    for (const Brick& b : topo.bricks)
        for (int i = 0; i < 64; ++i)
            if ((b.mask >> i) & 1u) cells.insert({int64_t(b.x) + (i & 3), int64_t(b.y) + ((i >> 2) & 3), int64_t(b.z) + (i >> 4), 0});
    for (const Tile& t : topo.tiles) cells.insert({t.x, t.y, t.z, t.log2Size});
    return cells;
}

void expectSameDag(const dag::ReducedDag& a, const dag::ReducedDag& b, const std::string& what) {
    EXPECT_EQ(a.origin, b.origin) << what;
    EXPECT_EQ(a.log2Size, b.log2Size) << what;
    EXPECT_EQ(a.root, b.root) << what;
    EXPECT_EQ(a.bricks, b.bricks) << what;
    EXPECT_EQ(a.brickRefcount, b.brickRefcount) << what;
    ASSERT_EQ(a.inner.size(), b.inner.size()) << what;
    for (size_t k = 0; k < a.inner.size(); ++k) {
        EXPECT_EQ(a.inner[k].nodes, b.inner[k].nodes) << what << ", level " << k + 3;
        EXPECT_EQ(a.inner[k].refcount, b.inner[k].refcount) << what << ", level " << k + 3;
    }
    EXPECT_EQ(a.svoNodeCount, b.svoNodeCount) << what;
}

// Every cube size from the smallest to just below the root, both modes.
void checkAllCubeSizes(const GridTopology& topo, const std::string& name, dag::BuildOptions options = {}) {
    for (bool symmetry : {true, false}) {
        options.symmetry = symmetry;
        const dag::ReducedDag whole = dag::buildDag(topo, options);
        const std::vector<uint64_t> wholeLeaves = encoding::encodeCompact(whole, true).leaves;
        const std::vector<uint16_t> wholeInner = encoding::encodeCompact(whole, true).inner;
        for (unsigned cube = 3; cube < whole.log2Size; ++cube) {
            const std::string what = name + ", cubes of 2^" + std::to_string(cube) + (symmetry ? ", SSVDAG" : ", SVDAG");
            const dag::ReducedDag merged = dag::buildDagByCubes(topo, options, cube);
            expectSameDag(merged, whole, what);
            const encoding::CompactDag compact = encoding::encodeCompact(merged, true);
            EXPECT_EQ(compact.inner, wholeInner) << what;
            EXPECT_EQ(compact.leaves, wholeLeaves) << what;
            if (cube == 3 || cube + 1 == whole.log2Size) { EXPECT_EQ(cellsOf(encoding::decodeTopology(compact)), cellsOf(topo)) << what; }
            if (::testing::Test::HasFailure()) return;
        }
    }
}

} // namespace

TEST(SubDagMerge, SymmetricShellEqualsTheInCoreBuildForEveryCubeSize) {
    // A shell symmetric about planes between voxels: many reflective matches,
    // across cube borders too.
    std::set<Voxel> voxels;
    for (int64_t z = -45; z <= 45; ++z)
        for (int64_t y = -45; y <= 45; ++y)
            for (int64_t x = -45; x <= 45; ++x) {
                const double r = std::sqrt((x + 0.5) * (x + 0.5) + (y + 0.5) * (y + 0.5) + (z + 0.5) * (z + 0.5));
                if (std::abs(r - 40.0) < 1.5) voxels.insert({x, y, z});
            }
    const GridTopology topo = topologyFromVoxels(voxels);
    checkAllCubeSizes(topo, "shell");
    dag::BuildOptions centred;
    centred.origin = std::array<int64_t, 3>{-64, -64, -64};  // centre planes through the shell's centre
    checkAllCubeSizes(topo, "centred shell", centred);
}

TEST(SubDagMerge, RandomClustersWithTilesOfEverySizeEqualTheInCoreBuild) {
    std::mt19937_64 rng(77);
    for (int trial = 0; trial < 12; ++trial) {
        std::set<Voxel> voxels;
        const int clusters = 1 + int(rng() % 6);
        for (int c = 0; c < clusters; ++c) {
            const int64_t cx = int64_t(rng() % 600) - 300, cy = int64_t(rng() % 600) - 300, cz = int64_t(rng() % 100);
            const int count = int(rng() % 500);
            for (int i = 0; i < count; ++i) voxels.insert({cx + int64_t(rng() % 24), cy + int64_t(rng() % 24), cz + int64_t(rng() % 24)});
        }
        GridTopology topo = topologyFromVoxels(voxels);
        // Tiles away from the voxels: lone ones of sizes 8..128, a full 2x2x2
        // block of 8^3 tiles (a parent of solid children), a 32^3 next to it.
        topo.tiles.push_back({1024, 1024, 0, 3});
        topo.tiles.push_back({1024 + 32, 1024, 32, 5});
        topo.tiles.push_back({2048, 0, 0, 7});
        topo.tiles.push_back({2048 + 128, 0, 0, 4});
        for (int32_t z = 0; z < 16; z += 8)
            for (int32_t y = 0; y < 16; y += 8)
                for (int32_t x = 0; x < 16; x += 8) topo.tiles.push_back({-2048 + x, y, z, 3});
        if (trial % 2) topo.tiles.push_back({-4096, -4096, -4096, 12});
        checkAllCubeSizes(topo, "trial " + std::to_string(trial));
        if (HasFailure()) return;
    }
}

TEST(SubDagMerge, Int32ExtremesEqualTheInCoreBuild) {
    GridTopology topo;
    const int32_t lo = std::numeric_limits<int32_t>::min(), hi = std::numeric_limits<int32_t>::max();
    topo.bricks.push_back({lo, lo, lo, 1});
    topo.bricks.push_back({hi - 3, hi - 3, hi - 3, uint64_t(1) << 63});
    topo.bricks.push_back({lo, hi - 3, 0, uint64_t(1) << brickBitIndex(0, 3, 0)});
    topo.tiles.push_back({0, 0, 0, 12});
    checkAllCubeSizes(topo, "extremes");
}

TEST(SubDagMerge, RejectsCubesOutOfOrder) {
    GridTopology topo;
    topo.bricks.push_back({0, 0, 0, 1});
    topo.bricks.push_back({64, 0, 0, 1});
    const dag::RootPlacement whole = dag::placeRoot(dag::activeBounds(topo), 4, {});
    dag::SubDagMerger merger(whole, 3, true);
    GridTopology one;
    one.bricks.push_back({64, 0, 0, 1});
    dag::BuildOptions local;
    local.origin = std::array<int64_t, 3>{64, 0, 0};
    local.log2Size = 3;
    merger.add({8, 0, 0}, dag::buildDag(one, local));
    EXPECT_THROW(merger.add({0, 0, 0}, dag::buildDag(one, local)), Error);
}
