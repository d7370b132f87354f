// The Summary section (docs/FORMAT.md 10.1) and `info` reading only what it
// prints:
// - the value range is the set's, not the order's: any order of the same
//   values (NaNs, -0.0 and +0.0 among them) gives the bits a sort of the
//   values that are not NaN gives;
// - the section an encode stores equals OpenVDB's own box, active tiles and
//   minMax of the source grid, on the in-memory and the cube-by-cube path;
// - `vdbdag info` of a file whose DAG and value payloads are corrupted
//   prints what it prints of the intact file (it never read them), while
//   `info --values` and `verify` refuse the corrupted file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Count.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "src/attributes/ValueRange.h"
#include "src/format/SsvdagContainer.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/VdbImport.h"

namespace fs = std::filesystem;
using namespace vdbdag;

namespace {

const fs::path& folder() {
    static const fs::path d = vdbdag::testing::testFolder("summary_section");
    return d;
}

std::vector<uint8_t> bytesOf(const std::vector<float>& v) {
    std::vector<uint8_t> b(v.size() * 4);
    std::memcpy(b.data(), v.data(), b.size());
    return b;
}

float floatOf(const std::vector<uint8_t>& b) {
    float f = 0;
    EXPECT_EQ(b.size(), 4u);
    std::memcpy(&f, b.data(), 4);
    return f;
}

// A d=32 level-set sphere with a box of active tiles beside it, written by OpenVDB.
fs::path sphereWithTiles() {
    openvdb::initialize();
    auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(14.0f, openvdb::Vec3f(1.0f, -3.0f, 2.0f), 0.5f, 3.0f);
    g->tree().addTile(1, openvdb::Coord(64, 0, 0), -1.5f, true);  // an active 8^3 tile
    g->setName("ball");
    const fs::path p = folder() / "ball.vdb";
    openvdb::io::File f(p.string());
    f.write({g});
    f.close();
    return p;
}

format::StoredSummary summaryOf(const fs::path& ssvdag) {
    format::ReadOptions options;
    options.keepValueWindows = true;
    const format::SsvdagScene scene = format::readSceneFile(ssvdag.string(), options);
    EXPECT_EQ(scene.grids.size(), 1u);
    EXPECT_TRUE(scene.grids.at(0).summary.has_value());
    return scene.grids.at(0).summary.value_or(format::StoredSummary{});
}

} // namespace

TEST(ValueRange, IsTheSetsNotTheOrders) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-3.0f, 3.0f);
    std::vector<float> values;
    for (int i = 0; i < 500; ++i) values.push_back(u(rng));
    values.push_back(std::nanf(""));
    values.push_back(-std::nanf("7"));
    values.push_back(0.0f);
    values.push_back(-0.0f);
    for (const bool zerosOnly : {false, true}) {
        std::vector<float> v = values;
        if (zerosOnly) v = {0.0f, std::nanf(""), -0.0f, 0.0f};
        // The reference: the values that are not NaN, sorted by value and
        // then sign (-0.0 first); the first and the last.
        std::vector<float> sorted;
        for (float f : v)
            if (!std::isnan(f)) sorted.push_back(f);
        std::sort(sorted.begin(), sorted.end(), [](float a, float b) { return a < b || (a == b && std::signbit(a) && !std::signbit(b)); });
        for (int trial = 0; trial < 20; ++trial) {
            std::shuffle(v.begin(), v.end(), rng);
            attributes::ValueRange whole, merged;
            whole.add(ValueType::Float, bytesOf(v));
            // In three parts, each its own range, merged (an encoder's shares).
            for (size_t part = 0; part < 3; ++part) {
                attributes::ValueRange r;
                const size_t a = v.size() * part / 3, b = v.size() * (part + 1) / 3;
                r.add(ValueType::Float, bytesOf(std::vector<float>(v.begin() + long(a), v.begin() + long(b))));
                merged.merge(ValueType::Float, r);
            }
            for (const attributes::ValueRange* r : {&whole, &merged}) {
                ASSERT_FALSE(r->empty());
                const float lo = floatOf(r->min), hi = floatOf(r->max);
                EXPECT_EQ(std::memcmp(&lo, &sorted.front(), 4), 0) << lo << " " << sorted.front();
                EXPECT_EQ(std::memcmp(&hi, &sorted.back(), 4), 0) << hi << " " << sorted.back();
            }
        }
    }
    attributes::ValueRange nans;
    nans.add(ValueType::Float, bytesOf({std::nanf(""), std::nanf("")}));
    EXPECT_TRUE(nans.empty());
}

// The Summary an encode stores, in memory and cube by cube, against OpenVDB's own figures of the source.
TEST(SummarySection, EncodesStoreOpenVdbsBoxTilesAndRange) {
    const fs::path vdb = sphereWithTiles();
    openvdb::io::File f(vdb.string());
    f.open();
    const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid("ball"));
    f.close();
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    const auto minMax = openvdb::tools::minMax(grid->tree());
    const uint64_t tiles = grid->tree().activeTileCount();
    ASSERT_GE(tiles, 1u);
    // In memory (pipeline::encodeVolume), and by the command line cube by cube in 16 MB.
    const fs::path inMemory = folder() / "ball_memory.ssvdag", byCubes = folder() / "ball_cubes.ssvdag";
    {
        const std::vector<uint8_t> bytes = format::writeScene(pipeline::encodeVolume(bridge::importVdb(vdb.string()).volume, {}));
        std::ofstream(inMemory, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    }
    const auto r = vdbdag::testing::runCli("encode " + vdb.string() + " -o " + byCubes.string() + " --force --memory-limit 16M");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const fs::path& out : {inMemory, byCubes}) {
        const std::string memory = out.filename().string();
        const format::StoredSummary s = summaryOf(out);
        ASSERT_TRUE(s.indexBox.has_value());
        EXPECT_EQ(s.indexBox->min, (std::array<int64_t, 3>{box.min().x(), box.min().y(), box.min().z()})) << memory;
        EXPECT_EQ(s.indexBox->max, (std::array<int64_t, 3>{box.max().x(), box.max().y(), box.max().z()})) << memory;
        EXPECT_EQ(s.solidNodes, tiles) << memory;
        EXPECT_EQ(floatOf(s.activeRange.min), minMax.min()) << memory;
        EXPECT_EQ(floatOf(s.activeRange.max), minMax.max()) << memory;
    }
}

// `info` reads neither the DAG nor the values: a file with both corrupted
// reports as the intact one does; what reads them refuses it.
TEST(SummarySection, InfoReadsNeitherTheDagNorTheValues) {
    const fs::path vdb = sphereWithTiles();
    const fs::path good = folder() / "info_good.ssvdag", bad = folder() / "info_bad.ssvdag";
    ASSERT_EQ(vdbdag::testing::runCli("encode " + vdb.string() + " -o " + good.string() + " --force").exitCode, 0);
    std::vector<uint8_t> bytes = format::readFileBytes(good.string());
    int corrupted = 0;
    for (const format::Section& s : format::storedSectionsOf(good.string())) {
        const bool dag = s.kind == format::SectionKind::DagInner || s.kind == format::SectionKind::DagLeaves;
        const bool values = s.kind == format::SectionKind::PredictedWindows || s.kind == format::SectionKind::ValueWindows;
        if (!dag && !values) continue;
        // A byte past the payload's start (a predicted window's coding byte
        // is read) and before its directory: the middle.
        ASSERT_GE(s.stored->storedBytes, 64u);
        bytes[size_t(s.stored->offset + s.stored->storedBytes / 2)] ^= 0x5A;
        ++corrupted;
    }
    ASSERT_GE(corrupted, 2);
    std::ofstream(bad, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    const auto a = vdbdag::testing::runCli("info " + good.string() + " --json");
    const auto b = vdbdag::testing::runCli("info " + bad.string() + " --json");
    ASSERT_EQ(a.exitCode, 0) << a.err;
    ASSERT_EQ(b.exitCode, 0) << b.err;
    nlohmann::json ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
    ja.erase("input"), jb.erase("input");
    EXPECT_EQ(ja, jb);
    EXPECT_TRUE(ja["grids"][0].contains("value_range"));
    for (const std::string& reads : {"info " + bad.string() + " --values", "verify " + bad.string()}) {
        const auto r = vdbdag::testing::runCli(reads);
        EXPECT_NE(r.exitCode, 0) << reads;
        EXPECT_NE(r.err.find(bad.string()), std::string::npos) << reads << ": " << r.err;
    }
}

// A Summary that says otherwise than its grid: `info` prints what it says
// (it reads no more), `info --values`, which reads every value, checks it
// against the DAG and values and refuses the file naming it.
TEST(SummarySection, InfoValuesRefusesASummaryItsGridContradicts) {
    const fs::path vdb = sphereWithTiles();
    const fs::path good = folder() / "lying_good.ssvdag", bad = folder() / "lying.ssvdag";
    ASSERT_EQ(vdbdag::testing::runCli("encode " + vdb.string() + " -o " + good.string() + " --force").exitCode, 0);
    for (const int forge : {0, 1, 2}) {
        format::SsvdagScene scene = format::readSceneFile(good.string());
        ASSERT_TRUE(scene.grids.at(0).summary);
        format::StoredSummary& s = *scene.grids[0].summary;
        if (forge == 0) s.solidNodes += 1;
        if (forge == 1) s.indexBox->max[2] += 4;
        if (forge == 2) std::swap(s.activeRange.min, s.activeRange.max);
        const std::vector<uint8_t> bytes = format::writeScene(scene);
        std::ofstream(bad, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        EXPECT_EQ(vdbdag::testing::runCli("info " + bad.string()).exitCode, 0) << forge;
        const auto r = vdbdag::testing::runCli("info " + bad.string() + " --values");
        EXPECT_EQ(r.exitCode, 1) << forge;
        EXPECT_NE(r.err.find(bad.string() + ": grid 0 'ball': its Summary section says"), std::string::npos) << forge << ": " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    EXPECT_EQ(vdbdag::testing::runCli("info " + good.string() + " --values").exitCode, 0);
}
