// The cube-by-cube comparison that `verify` uses (vdb_bridge/VdbStreamCompare.h)
// must find what the whole-grid comparison finds (VdbCompare.h: OpenVDB's
// topologyDifference and accessors over two whole grids), difference by
// difference, on files changed from the one encoded: a value, a voxel
// switched off or on, a leaf and a tile added, inactive values changed,
// metadata, a grid missing. And `verify` itself, now region by region,
// reports the size `encode` writes and leaves nothing in its scratch folder.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>

#include "src/format/SsvdagFile.h"
#include "src/pipeline/CubeEncoder.h"
#include "src/pipeline/GridCodec.h"
#include "tests/unit/CliRunner.h"
#include "tests/unit/TestInputs.h"
#include "vdb_bridge/VdbCompare.h"
#include "vdb_bridge/VdbCubes.h"
#include "vdb_bridge/VdbImport.h"
#include "vdb_bridge/VdbStreamCompare.h"

using namespace vdbdag;
namespace fs = std::filesystem;

namespace {

fs::path tempDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_stream_compare_" + std::to_string(getpid()));
        fs::remove_all(d);
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

// A level-set-like float grid (voxels scattered over many cubes, so leaves
// straddle cube boundaries; inactive values that are not the background;
// tiles at two levels), an int grid with a tile, a vec3 grid and a mask.
openvdb::GridPtrVec makeGrids() {
    openvdb::initialize();
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> spread(-300, 300);
    auto f = openvdb::FloatGrid::create(3.0f);
    f->setName("density");
    f->setGridClass(openvdb::GRID_LEVEL_SET);
    auto acc = f->getAccessor();
    for (int i = 0; i < 6000; ++i) {
        const openvdb::Coord c(spread(rng), spread(rng), spread(rng) / 3);
        acc.setValueOn(c, float(rng() % 17) * 0.125f);
        acc.setValueOff(c.offsetBy(0, 1, 0), -3.0f);
    }
    f->tree().addTile(1, openvdb::Coord(1024, 0, 0), 1.5f, true);
    f->tree().addTile(2, openvdb::Coord(128 * 20, 128 * 3, 0), -3.0f, false);
    f->tree().addTile(2, openvdb::Coord(-128 * 20, 128 * 3, 0), 2.5f, true);
    auto labels = openvdb::Int32Grid::create(0);
    labels->setName("labels");
    auto colour = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    colour->setName("Cd");
    auto mask = openvdb::MaskGrid::create();
    mask->setName("mask");
    for (int i = 0; i < 3000; ++i) {
        const openvdb::Coord c(spread(rng), spread(rng) / 2, spread(rng));
        labels->tree().setValueOn(c, c.x() / 16);
        colour->tree().setValueOn(c, openvdb::Vec3s(float(rng() % 4), 0.5f, float(c.z())));
        mask->tree().setValueOn(c.offsetBy(0, 0, 5));
    }
    labels->tree().addTile(1, openvdb::Coord(512, 512, 512), 7, true);
    return {f, labels, colour, mask};
}

fs::path writeFile(const std::string& name, const openvdb::GridPtrVec& grids, const std::string& creator = "test_stream_compare") {
    const fs::path path = tempDir() / (name + ".vdb");
    openvdb::MetaMap meta;
    meta.insertMeta("creator", openvdb::StringMetadata(creator));
    openvdb::io::File file(path.string());
    file.write(grids, meta);
    file.close();
    return path;
}

openvdb::GridPtrVec deepCopies(const openvdb::GridPtrVec& grids) {
    openvdb::GridPtrVec out;
    for (const auto& g : grids) out.push_back(g->deepCopyGrid());
    return out;
}

// The original file encoded region by region and read back as `verify` reads it.
format::SsvdagScene encodedScene(const fs::path& original) {
    bridge::VdbCubeInput input = bridge::openVdbCubes(original.string());
    pipeline::CubeBudget budget;
    budget.cubeLog2 = 6;
    const std::vector<uint8_t> bytes =
        format::writeScene(pipeline::encodeSourcesByCubes(std::move(input.grids), input.fileMetadata, {}, budget));
    const fs::path encoded = tempDir() / (original.stem().string() + ".ssvdag");
    std::ofstream(encoded, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    format::ReadOptions options;
    options.keepValueWindows = true;
    return format::readSceneFile(encoded.string(), options);
}

uint64_t onlyInFile(const bridge::CompareResult& r) { return r.topology.empty() ? 0 : r.topology[0].onlyInA; }
uint64_t onlyInDecoded(const bridge::CompareResult& r) { return r.topology.empty() ? 0 : r.topology[0].onlyInB; }
uint64_t activeValues(const bridge::CompareResult& r) { return r.values.empty() ? 0 : r.values[0].activeValues; }
uint64_t inactiveValues(const bridge::CompareResult& r) { return r.values.empty() ? 0 : r.values[0].inactiveValues; }

struct Change {
    std::string name;
    std::function<void(openvdb::GridPtrVec&)> apply;
    // The two comparisons count value differences alike. They do not for a
    // tile (the whole comparison counts it once, the other per voxel) nor for
    // a voxel in one grid only (counted as a value difference too by one).
    bool sameValueCounts;
};

openvdb::FloatGrid& density(openvdb::GridPtrVec& grids) { return static_cast<openvdb::FloatGrid&>(*grids[0]); }

// A voxel of the density grid that is active, and one with an inactive
// value that is not the background.
openvdb::Coord firstActive(openvdb::GridPtrVec& grids) {
    for (auto it = density(grids).tree().cbeginLeaf(); it; ++it)
        if (auto on = it->cbeginValueOn()) return on.getCoord();
    return {};
}
openvdb::Coord firstStoredInactive(openvdb::GridPtrVec& grids) {
    for (auto it = density(grids).tree().cbeginLeaf(); it; ++it)
        for (auto off = it->cbeginValueOff(); off; ++off)
            if (*off != 3.0f) return off.getCoord();
    return {};
}

} // namespace

TEST(StreamCompare, AnUnchangedFileIsIdentical) {
    const fs::path original = writeFile("original", makeGrids());
    const format::SsvdagScene scene = encodedScene(original);
    const bridge::CompareResult r = bridge::compareSceneWithFile(original.string(), scene);
    EXPECT_TRUE(r.identical) << (r.headerDifferences.empty() ? "" : r.headerDifferences[0]) << " / " << r.topology.size() << " topology, "
                             << r.values.size() << " value differences";
    EXPECT_TRUE(bridge::compareWithFile(original.string(), pipeline::decodeScene(encodedScene(original))).identical);
}

TEST(StreamCompare, FindsWhatTheWholeGridComparisonFinds) {
    const openvdb::GridPtrVec grids = makeGrids();
    const fs::path original = writeFile("base", grids);
    const format::SsvdagScene scene = encodedScene(original);
    const Volume decoded = pipeline::decodeScene(encodedScene(original));
    const std::vector<Change> changes = {
        {"an active value", [](auto& g) { density(g).tree().setValueOn(firstActive(g), 99.0f); }, true},
        {"a voxel switched off", [](auto& g) { density(g).tree().setValueOff(firstActive(g)); }, false},
        {"a voxel switched on", [](auto& g) { density(g).tree().setValueOn(firstStoredInactive(g)); }, false},
        // (The whole comparison also counts these voxels' values against the background.)
        {"a new leaf far away", [](auto& g) { density(g).tree().setValueOn(openvdb::Coord(5000, -7000, 333), 1.0f); }, false},
        {"a new active tile", [](auto& g) { density(g).tree().addTile(1, openvdb::Coord(-4096, 0, 0), 1.0f, true); }, false},
        {"an inactive value changed", [](auto& g) { density(g).tree().setValueOff(firstStoredInactive(g), -2.0f); }, true},
        {"an inactive value set to the background", [](auto& g) { density(g).tree().setValueOff(firstStoredInactive(g), 3.0f); }, true},
        {"an inactive tile's value", [](auto& g) { density(g).tree().addTile(2, openvdb::Coord(128 * 20, 128 * 3, 0), -1.0f, false); }, false},
        {"an active tile's value", [](auto& g) { density(g).tree().addTile(1, openvdb::Coord(1024, 0, 0), 1.25f, true); }, false},
        {"a vec3 value", [](auto& g) {
             auto& c = static_cast<openvdb::Vec3SGrid&>(*g[2]);
             c.tree().setValueOn(c.tree().cbeginValueOn().getCoord(), openvdb::Vec3s(-1.0f));
         }, true},
        {"a mask voxel", [](auto& g) { static_cast<openvdb::MaskGrid&>(*g[3]).tree().setValueOn(openvdb::Coord(-999, 0, 0)); }, true},
    };
    for (const Change& change : changes) {
        SCOPED_TRACE(change.name);
        openvdb::GridPtrVec changed = deepCopies(grids);
        change.apply(changed);
        const fs::path file = writeFile("changed", changed);
        const bridge::CompareResult byCubes = bridge::compareSceneWithFile(file.string(), scene);
        const bridge::CompareResult whole = bridge::compareWithFile(file.string(), decoded);
        ASSERT_FALSE(whole.identical);
        EXPECT_FALSE(byCubes.identical);
        EXPECT_EQ(byCubes.headerDifferences, whole.headerDifferences);
        ASSERT_EQ(byCubes.topology.size(), whole.topology.size());
        EXPECT_EQ(onlyInFile(byCubes), onlyInFile(whole));
        EXPECT_EQ(onlyInDecoded(byCubes), onlyInDecoded(whole));
        if (!byCubes.topology.empty()) { EXPECT_EQ(byCubes.topology[0].gridIndex, whole.topology[0].gridIndex); }
        if (change.sameValueCounts) {
            EXPECT_EQ(activeValues(byCubes), activeValues(whole));
            EXPECT_EQ(inactiveValues(byCubes), inactiveValues(whole));
        }
    }
}

TEST(StreamCompare, FindsChangedMetadataAndAMissingGrid) {
    const openvdb::GridPtrVec grids = makeGrids();
    const format::SsvdagScene scene = encodedScene(writeFile("base_meta", grids));
    const bridge::CompareResult creator = bridge::compareSceneWithFile(writeFile("other_creator", deepCopies(grids), "someone else").string(), scene);
    ASSERT_EQ(creator.headerDifferences.size(), 1u);
    EXPECT_NE(creator.headerDifferences[0].find("file metadata 'creator'"), std::string::npos) << creator.headerDifferences[0];
    openvdb::GridPtrVec renamed = deepCopies(grids);
    renamed[1]->setName("segments");
    const bridge::CompareResult name = bridge::compareSceneWithFile(writeFile("renamed", renamed).string(), scene);
    ASSERT_FALSE(name.headerDifferences.empty());
    EXPECT_NE(name.headerDifferences[0].find("name differs"), std::string::npos) << name.headerDifferences[0];
    openvdb::GridPtrVec fewer = deepCopies(grids);
    fewer.pop_back();
    const bridge::CompareResult missing = bridge::compareSceneWithFile(writeFile("fewer", fewer).string(), scene);
    ASSERT_FALSE(missing.headerDifferences.empty());
    EXPECT_NE(missing.headerDifferences[0].find("grid count differs (3 vs 4)"), std::string::npos) << missing.headerDifferences[0];
}

TEST(StreamCompare, VerifyReportsTheSizeEncodeWritesAndLeavesNoScratch) {
    const fs::path original = writeFile("for_verify", makeGrids());
    const fs::path scratch = tempDir() / "scratch", encoded = tempDir() / "for_verify.ssvdag";
    fs::create_directories(scratch);
    vdbdag::testing::CommandResult r = vdbdag::testing::runCli("encode " + original.string() + " -o " + encoded.string() + " -f");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = vdbdag::testing::runCli("verify " + original.string() + " --memory-limit 64M --scratch " + scratch.string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_TRUE(report["identical"].get<bool>());
    EXPECT_EQ(report["ssvdag_bytes"].get<uint64_t>(), fs::file_size(encoded));
    EXPECT_TRUE(fs::is_empty(scratch));
    // --encoded checks the file encode wrote; against another input it fails, naming the difference.
    r = vdbdag::testing::runCli("verify " + original.string() + " --encoded " + encoded.string());
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    openvdb::GridPtrVec changed = makeGrids();
    density(changed).tree().setValueOn(openvdb::Coord(5000, -7000, 333), 1.0f);
    r = vdbdag::testing::runCli("verify " + writeFile("changed_for_verify", changed).string() + " --encoded " + encoded.string());
    EXPECT_EQ(r.exitCode, 1) << r.out << r.err;
    EXPECT_NE(r.out.find("1 voxels only in the original"), std::string::npos) << r.out;
    // A failure leaves nothing either: an input that is not a .vdb file.
    const fs::path bad = tempDir() / "not_a.vdb";
    std::ofstream(bad) << "not a vdb file";
    r = vdbdag::testing::runCli("verify " + bad.string() + " --scratch " + scratch.string());
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(scratch));
}

TEST(StreamCompare, SharedDataFilesAreIdentical) {
    const auto files = vdbdag::testing::sharedVdbFiles();
    if (files.empty()) GTEST_SKIP() << "no shared data";
    for (const fs::path& file : files) {
        if (fs::file_size(file) > (64u << 20)) continue;  // the large ones are the scale scripts' business
        SCOPED_TRACE(file.string());
        bridge::ImportOptions skip;
        skip.skipUnsupported = true;
        if (!bridge::canReadVdbByCubes(file.string())) continue;
        bridge::VdbCubeInput input = bridge::openVdbCubes(file.string(), skip);
        if (input.grids.size() != bridge::importVdb(file.string(), skip).volume.grids.size() || !input.warnings.empty()) continue;
        const format::SsvdagScene scene = encodedScene(file);
        const bridge::CompareResult r = bridge::compareSceneWithFile(file.string(), scene);
        EXPECT_TRUE(r.identical) << (r.headerDifferences.empty() ? "" : r.headerDifferences[0]);
    }
}
