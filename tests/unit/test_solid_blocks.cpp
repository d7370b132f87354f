// A dense scan's solid 8^3 blocks (vdb_bridge/detail/SolidBlocks.h: all
// 512 samples kept, one value) become tiles, one attribute entry each
// (issue 39 item 1). Checked against a brute-force walk over the samples
// written here: which blocks are solid, the tiles the import and the cube
// source give, the file's solid nodes, the same bytes under every memory
// limit, thread and process count, and the samples decoded back;
// `--no-tiles` keeps every voxel in its brick.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include <nlohmann/json.hpp>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/DenseImport.h"

namespace fs = std::filesystem;
using vdbdag::testing::runCli;
using vdbdag::testing::runShell;

namespace {

constexpr int kNx = 44, kNy = 27, kNz = 21;  // partial blocks and bricks on three faces

fs::path workDir() {
    static const fs::path dir = vdbdag::testing::testFolder("solid_blocks");
    return dir;
}

// A label volume: four regions split by planes that do not fall on the
// 8-grid (so some blocks are mixed), 0 outside a ball, and a column of
// noise that spoils the blocks it crosses.
std::vector<uint8_t> labels() {
    std::vector<uint8_t> v;
    std::mt19937 rng(5);
    for (int z = 0; z < kNz; ++z)
        for (int y = 0; y < kNy; ++y)
            for (int x = 0; x < kNx; ++x) {
                const bool inside = (x - 22) * (x - 22) + (y - 13) * (y - 13) + (z - 10) * (z - 10) < 15 * 15;
                uint8_t label = inside ? uint8_t(1 + (x >= 19) + 2 * (z >= 13)) : 0;
                if (x >= 30 && x < 33 && y >= 2 && y < 6) label = uint8_t(10 + rng() % 3);
                v.push_back(label);
            }
    return v;
}

fs::path writeRaw(const std::vector<uint8_t>& v) {
    const fs::path raw = workDir() / ("labels_" + std::to_string(kNx) + "x" + std::to_string(kNy) + "x" + std::to_string(kNz) + "_uint8.raw");
    std::ofstream(raw, std::ios::binary).write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size()));
    return raw;
}

uint8_t at(const std::vector<uint8_t>& v, int x, int y, int z) { return v[(size_t(z) * kNy + size_t(y)) * kNx + size_t(x)]; }

// Brute force: the aligned 8^3 blocks wholly inside the volume whose
// samples are all equal, with that value.
std::map<std::tuple<int, int, int>, int32_t> solidBlocks(const std::vector<uint8_t>& v) {
    std::map<std::tuple<int, int, int>, int32_t> out;
    for (int z = 0; z + 8 <= kNz; z += 8)
        for (int y = 0; y + 8 <= kNy; y += 8)
            for (int x = 0; x + 8 <= kNx; x += 8) {
                bool same = true;
                for (int k = 0; k < 512 && same; ++k) same = at(v, x + (k & 7), y + ((k >> 3) & 7), z + (k >> 6)) == at(v, x, y, z);
                if (same) out[{x, y, z}] = at(v, x, y, z);
            }
    return out;
}

using Tiles = std::map<std::tuple<int, int, int>, int32_t>;
Tiles tilesOf(const vdbdag::GridTopology& t, const vdbdag::LayerValues& values) {
    Tiles out;
    EXPECT_EQ(values.tiles.size(), t.tiles.size() * 4);
    for (size_t i = 0; i < t.tiles.size(); ++i) {
        EXPECT_EQ(t.tiles[i].log2Size, 3);
        int32_t value = 0;
        if (values.tiles.size() >= (i + 1) * 4) std::memcpy(&value, values.tiles.data() + i * 4, 4);
        EXPECT_TRUE(out.emplace(std::tuple{t.tiles[i].x, t.tiles[i].y, t.tiles[i].z}, value).second) << "a tile twice";
    }
    return out;
}

// No brick lies in a tile; every sample outside the tiles is in a brick with its value.
void expectBricksAreTheRest(const vdbdag::GridTopology& t, const vdbdag::LayerValues& values, const Tiles& tiles, const std::vector<uint8_t>& v) {
    size_t at_ = 0, voxels = 0;
    for (const vdbdag::Brick& b : t.bricks) {
        EXPECT_FALSE(tiles.count({b.x & ~7, b.y & ~7, b.z & ~7})) << "a brick inside a tile";
        for (int bit = 0; bit < 64; ++bit) {
            if (!((b.mask >> bit) & 1)) continue;
            int32_t value;
            std::memcpy(&value, values.bricks.data() + at_, 4);
            at_ += 4;
            EXPECT_EQ(value, at(v, b.x + (bit & 3), b.y + ((bit >> 2) & 3), b.z + (bit >> 4)));
            ++voxels;
        }
    }
    EXPECT_EQ(at_, values.bricks.size());
    EXPECT_EQ(voxels + 512 * tiles.size(), v.size());
}

} // namespace

TEST(SolidBlocks, TheImportAndTheCubeSourceGiveTheSolidBlocksAsTiles) {
    const std::vector<uint8_t> v = labels();
    const fs::path raw = writeRaw(v);
    const auto expected = solidBlocks(v);
    ASSERT_GE(expected.size(), 4u);  // the test means something
    ASSERT_LT(expected.size(), size_t((kNx / 8) * (kNy / 8) * (kNz / 8)));

    vdbdag::bridge::DenseImportOptions options;
    options.showProgress = false;
    const vdbdag::bridge::DenseImportResult whole = vdbdag::bridge::importDense(raw.string(), options);
    const vdbdag::GridRecord& record = whole.volume.grids.at(0);
    const Tiles tiles = tilesOf(record.topology, record.values);
    EXPECT_TRUE(tiles == Tiles(expected.begin(), expected.end()));
    expectBricksAreTheRest(record.topology, record.values, tiles, v);

    options.cubesNear = (workDir() / "x").string();
    vdbdag::bridge::DenseImportResult cubes = vdbdag::bridge::importDense(raw.string(), options);
    vdbdag::CubeSource& source = *cubes.cubes.at(0);
    const vdbdag::LayerSummary s = source.summary(vdbdag::Layer::Active);
    EXPECT_EQ(s.tiles, expected.size());
    EXPECT_EQ(s.bricks, record.topology.bricks.size());
    EXPECT_EQ(s.voxels, v.size());
    EXPECT_EQ(s.largestTileLog2, 3u);
    for (const unsigned log2 : {3u, 4u, 6u}) {
        SCOPED_TRACE("cube size 2^" + std::to_string(log2));
        const std::array<int64_t, 3> origin{-8, 0, -16};
        source.cubes(vdbdag::Layer::Active, origin, log2);
        source.beginPass(vdbdag::Layer::Active, origin, log2, true);
        vdbdag::GridTopology all;
        vdbdag::LayerValues allValues;
        for (const vdbdag::CubeLoad& load : source.cubes(vdbdag::Layer::Active, origin, log2)) {
            vdbdag::GridTopology t;
            vdbdag::LayerValues values;
            source.read(load.cell, t, values);
            all.bricks.insert(all.bricks.end(), t.bricks.begin(), t.bricks.end());
            all.tiles.insert(all.tiles.end(), t.tiles.begin(), t.tiles.end());
            allValues.bricks.insert(allValues.bricks.end(), values.bricks.begin(), values.bricks.end());
            allValues.tiles.insert(allValues.tiles.end(), values.tiles.begin(), values.tiles.end());
        }
        source.endPass();
        EXPECT_TRUE(tilesOf(all, allValues) == tiles);
        expectBricksAreTheRest(all, allValues, tiles, v);
    }

    // --no-tiles (DenseImportOptions::solidBlocks false): bricks only.
    options.cubesNear.clear();
    options.solidBlocks = false;
    const vdbdag::bridge::DenseImportResult plain = vdbdag::bridge::importDense(raw.string(), options);
    EXPECT_TRUE(plain.volume.grids.at(0).topology.tiles.empty());
    expectBricksAreTheRest(plain.volume.grids.at(0).topology, plain.volume.grids.at(0).values, {}, v);
}

TEST(SolidBlocks, AFileStoresEachSolidBlockOnceAndDecodesToTheSamples) {
    const std::vector<uint8_t> v = labels();
    const fs::path raw = writeRaw(v);
    const size_t solid = solidBlocks(v).size();
    const fs::path ss = workDir() / "labels.ssvdag", plain = workDir() / "labels_no_tiles.ssvdag";
    auto r = runCli("encode " + raw.string() + " -o " + ss.string() + " -f");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = runCli("encode " + raw.string() + " --no-tiles -o " + plain.string() + " -f");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const auto& [file, tiles] : {std::pair{ss, solid}, std::pair{plain, size_t(0)}}) {
        r = runCli("info " + file.string() + " --json");
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const auto info = nlohmann::json::parse(r.out);
        EXPECT_EQ(info["grids"][0]["active_voxels"].get<uint64_t>(), v.size()) << file;
        EXPECT_EQ(info["grids"][0]["solid_nodes"].get<uint64_t>(), tiles) << file;
    }
    // The same bytes cube by cube, on one thread.
    for (const std::string variant : {"--memory-limit 64K", "--memory-limit 1M --threads 1"}) {
        const fs::path out = workDir() / "labels_limited.ssvdag";
        ASSERT_EQ(runCli("encode " + raw.string() + " " + variant + " -o " + out.string() + " -f").exitCode, 0) << variant;
        EXPECT_EQ(runShell("cmp " + ss.string() + " " + out.string()).exitCode, 0) << variant;
    }
    // Decoded to raw, to NIfTI (by cubes) and to .nii.gz (the whole-grid writer): the samples.
    const fs::path back = workDir() / "labels_back.raw";
    ASSERT_EQ(runCli("decode " + ss.string() + " -o " + back.string() + " -f").exitCode, 0);
    std::vector<uint8_t> got(v.size());
    std::ifstream(back, std::ios::binary).read(reinterpret_cast<char*>(got.data()), std::streamsize(got.size()));
    EXPECT_TRUE(got == v);
    EXPECT_EQ(fs::file_size(back), v.size());
    const fs::path nii = workDir() / "labels_back.nii", gz = workDir() / "labels_back.nii.gz";
    ASSERT_EQ(runCli("decode " + ss.string() + " -o " + nii.string() + " -f").exitCode, 0);
    EXPECT_EQ(runShell("cmp -i " + std::to_string(fs::file_size(nii) - v.size()) + ":0 " + nii.string() + " " + raw.string()).exitCode, 0);
    ASSERT_EQ(runCli("decode " + ss.string() + " -o " + gz.string() + " -f").exitCode, 0);
    EXPECT_EQ(runShell("gzip -dc " + gz.string() + " | cmp - " + nii.string()).exitCode, 0);
}

// Three processes, cube by cube, write the single process's bytes: the
// solid blocks are decided from the samples, never from a rank's cubes.
TEST(SolidBlocks, MpirunGivesTheSingleProcessBytes) {
#if !defined(VDBDAG_MPI_BINARY)
    GTEST_SKIP() << "vdbdag-mpi not built (no MPI found)";
#else
    const fs::path raw = writeRaw(labels());
    const fs::path single = workDir() / "mpi_single.ssvdag", out = workDir() / "mpi_np3.ssvdag";
    ASSERT_EQ(runCli("encode " + raw.string() + " -o " + single.string() + " -f").exitCode, 0);
    const std::string command = std::string(VDBDAG_MPIRUN) + " --oversubscribe --allow-run-as-root -np 3 " + VDBDAG_MPI_BINARY + " encode " +
                                raw.string() + " -o " + out.string() + " -f --memory-limit 64K";
    const auto run = runShell(command);
    ASSERT_EQ(run.exitCode, 0) << command << "\n" << run.err;
    EXPECT_EQ(runShell("cmp " + single.string() + " " + out.string()).exitCode, 0);
#endif
}
