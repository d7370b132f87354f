// The cube-by-cube encoder (pipeline/CubeEncoder.h) against encodeGrid on
// the whole grid: the written files must be byte-identical for every cube
// size and worker count, and decode to the input (independent brute-force
// walk, selftest::flatten).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include "src/format/SsvdagFile.h"
#include "src/pipeline/CubeEncoder.h"
#include "src/pipeline/CubeTeam.h"
#include "src/pipeline/GridCodec.h"
#include "src/selftest/SyntheticGrid.h"
#include "src/util/Error.h"
#include "src/volume/CubeSource.h"

using namespace vdbdag;

namespace {

std::vector<uint8_t> fileOf(format::EncodedGrid grid) {
    format::SsvdagScene scene;
    scene.grids.push_back(std::move(grid));
    return format::writeScene(scene);
}

// A float shell with an inactive "inside" layer, tiles of 8^3 and 32^3 and
// a 128^3 tile larger than the small cubes.
GridRecord shellGrid(std::mt19937& rng) {
    selftest::SyntheticGrid active, inside;
    for (int z = -30; z <= 30; ++z)
        for (int y = -30; y <= 30; ++y)
            for (int x = -30; x <= 30; ++x) {
                const double r = std::sqrt((x + 0.5) * (x + 0.5) + (y + 0.5) * (y + 0.5) + (z + 0.5) * (z + 0.5));
                const float d = float(r - 26.0);
                if (std::abs(d) < 1.5f) {
                    const float v = (rng() % 4 == 0) ? float(rng() % 7) : d;  // some repeats for the palettes
                    active.addVoxel(x, y, z, &v);
                } else if (d < 0 && (x + y + z) % 3 != 0) {
                    const float v = -3.0f;
                    inside.addVoxel(x, y, z, &v);
                }
            }
    for (int i = 0; i < 4; ++i) {
        const float v = float(i);
        active.addTile({64 + 8 * i, 0, 0, 3}, &v);
    }
    const float t32 = 5.0f, t128 = -1.0f;
    active.addTile({128, 128, 0, 5}, &t32);
    active.addTile({256, 0, 256, 7}, &t128);
    inside.addTile({-64, -64, -64, 5}, &t32);
    GridRecord record = selftest::toRecord(active, "shell");
    const GridRecord in = selftest::toRecord(inside, "inside");
    record.inactiveTopology = in.topology;
    record.inactiveValues = in.values;
    return record;
}

GridRecord intGrid(std::mt19937& rng) {
    selftest::SyntheticGrid g;
    g.type = ValueType::Int32;
    std::set<std::array<int32_t, 3>> seen;
    for (int i = 0; i < 6000; ++i) {
        const int32_t x = int32_t(rng() % 200) - 100, y = int32_t(rng() % 50), z = int32_t(rng() % 200);
        const int32_t v = x / 8 + int32_t(rng() % 3);
        if (seen.insert({x, y, z}).second) g.addVoxel(x, y, z, &v);
    }
    return selftest::toRecord(g, "labels");
}

void expectSameFileForAllCubeSizes(const GridRecord& grid, const pipeline::EncodeOptions& options, const std::string& what) {
    const std::vector<uint8_t> whole = fileOf(pipeline::encodeGrid(grid, options));
    const auto source = recordCubes(grid);
    for (unsigned cube = 3; cube <= 9; ++cube)
        for (unsigned workers : {1u, 3u}) {
            pipeline::CubeBudget budget;
            budget.cubeLog2 = cube;
            budget.workers = workers;
            const format::EncodedGrid byCubes = pipeline::encodeGridByCubes(*source, options, budget);
            EXPECT_EQ(fileOf(byCubes), whole) << what << ", cubes of 2^" << cube << ", " << workers << " workers";
            if (cube == 3 && workers == 1 && options.tolerance.mode == attributes::ScalarTolerance::Mode::Exact) {
                const GridRecord decoded = pipeline::decodeGrid(byCubes);
                EXPECT_EQ(selftest::firstDifference(selftest::flatten(grid), selftest::flatten(decoded)), "") << what;
            }
            if (::testing::Test::HasFailure()) return;
        }
}

} // namespace

TEST(CubeEncoder, ShellWithTilesAndInactiveLayerIsByteIdenticalForEveryCubeSize) {
    std::mt19937 rng(5);
    const GridRecord grid = shellGrid(rng);
    pipeline::EncodeOptions options;
    expectSameFileForAllCubeSizes(grid, options, "shell");
    options.placementTrials = 3;
    options.computeSvdagStats = true;
    expectSameFileForAllCubeSizes(grid, options, "shell, 3 placements");
    options.symmetry = false;
    expectSameFileForAllCubeSizes(grid, options, "shell, SVDAG");
}

TEST(CubeEncoder, LossyAndIntegerCodingsAreByteIdentical) {
    std::mt19937 rng(9);
    const GridRecord shell = shellGrid(rng);
    pipeline::EncodeOptions lossy;
    lossy.tolerance.mode = attributes::ScalarTolerance::Mode::Absolute;
    lossy.tolerance.bound = 0.01;
    expectSameFileForAllCubeSizes(shell, lossy, "shell, tolerance 0.01");
    lossy.tolerance.mode = attributes::ScalarTolerance::Mode::Relative;
    lossy.tolerance.bound = 0.05;
    expectSameFileForAllCubeSizes(shell, lossy, "shell, relative tolerance 0.05");
    const GridRecord labels = intGrid(rng);
    expectSameFileForAllCubeSizes(labels, {}, "int32 labels");
    // Several placements: each candidate's values are coded (and, lossy,
    // quantised afresh) in its own order, in both encoders alike.
    lossy.placementTrials = 3;
    expectSameFileForAllCubeSizes(shell, lossy, "shell, relative tolerance 0.05, 3 placements");
    pipeline::EncodeOptions trials;
    trials.placementTrials = 3;
    expectSameFileForAllCubeSizes(labels, trials, "int32 labels, 3 placements");
}

TEST(CubeEncoder, ChoosesSmallerCubesForASmallerBudget) {
    std::mt19937 rng(1);
    const GridRecord grid = shellGrid(rng);
    const auto source = recordCubes(grid);
    pipeline::CubeBudget roomy, tight;
    roomy.bytes = 1ull << 30;
    tight.bytes = 64 * pipeline::cubeBytesPerBrick(4);  // one worker's share fits a few bricks
    tight.workers = roomy.workers = 1;
    EXPECT_EQ(fileOf(pipeline::encodeGridByCubes(*source, {}, tight)), fileOf(pipeline::encodeGrid(grid)));
    EXPECT_EQ(fileOf(pipeline::encodeGridByCubes(*source, {}, roomy)), fileOf(pipeline::encodeGrid(grid)));
}

// A source that cannot give normals (as a .vdb read region by region).
class WithoutNormals final : public CubeSource {
public:
    explicit WithoutNormals(CubeSource& inner) : inner_(inner) {}
    const GridRecord& header() const override { return inner_.header(); }
    LayerSummary summary(Layer layer) override { return inner_.summary(layer); }
    std::vector<CubeLoad> cubes(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2) override { return inner_.cubes(layer, origin, log2); }
    void largeTiles(Layer layer, unsigned log2, GridTopology& tiles, LayerValues& values) override { inner_.largeTiles(layer, log2, tiles, values); }
    void beginPass(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2, bool withValues) override {
        inner_.beginPass(layer, origin, log2, withValues);
    }
    void read(const CubeCell& cell, GridTopology& topology, LayerValues& values) override { inner_.read(cell, topology, values); }
    void endPass() override { inner_.endPass(); }

private:
    CubeSource& inner_;
};

// --normals through the one encoder: a grid in memory gives its normals as
// a channel of its own, gathered in the values' attribute order at every
// cube size and worker count (the same file); a source without normals is
// refused. (test_normals checks the stored normals against closed forms.)
TEST(CubeEncoder, NormalsAreAChannelOfTheSource) {
    std::mt19937 rng(1);
    GridRecord grid = shellGrid(rng);
    const uint64_t entries = grid.values.bricks.size() / 4 + grid.values.tiles.size() / 4;
    GridNormals normals;
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (uint64_t i = 0; i < entries; ++i) {
        std::array<float, 3> v{n(rng), n(rng), n(rng)};
        const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (float& c : v) c /= len;
        auto& out = i < grid.values.bricks.size() / 4 ? normals.vectors.bricks : normals.vectors.tiles;
        out.insert(out.end(), reinterpret_cast<const uint8_t*>(v.data()), reinterpret_cast<const uint8_t*>(v.data()) + sizeof v);
    }
    grid.normals = normals;
    pipeline::EncodeOptions options;
    options.normalBits = 16;
    const format::EncodedGrid encoded = pipeline::encodeGrid(grid, options);
    ASSERT_TRUE(encoded.normals.has_value());
    EXPECT_EQ(encoded.normals->report.entries, entries);
    expectSameFileForAllCubeSizes(grid, options, "shell with normals");
    const auto source = recordCubes(grid);
    WithoutNormals refusing(*source);
    EXPECT_THROW(pipeline::encodeGridByCubes(refusing, options, {}), Error);
    options.normalBits = 0;
    EXPECT_EQ(fileOf(pipeline::encodeGridByCubes(refusing, options, {})), fileOf(pipeline::encodeGrid(grid, options)));
}

TEST(CubeTeam, SplitByWeightGivesContiguousBalancedShares) {
    using pipeline::splitByWeight;
    EXPECT_EQ(splitByWeight({1, 1, 1, 1}, 2), (std::vector<size_t>{0, 2, 4}));
    EXPECT_EQ(splitByWeight({1, 1, 1, 1, 1, 1}, 3), (std::vector<size_t>{0, 2, 4, 6}));
    EXPECT_EQ(splitByWeight({9, 1, 1, 1}, 2), (std::vector<size_t>{0, 1, 4}));  // the heavy item alone
    EXPECT_EQ(splitByWeight({}, 3), (std::vector<size_t>{0, 0, 0, 0}));
    EXPECT_EQ(splitByWeight({5}, 3).back(), 1u);
    const auto one = splitByWeight({3, 4}, 1);
    EXPECT_EQ(one, (std::vector<size_t>{0, 2}));
}
