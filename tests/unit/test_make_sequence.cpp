// samples/make_sequence.cpp (vdbdag_make_sequence, issue 43's test data)
// read back with OpenVDB: every frame a level set named "surface" with its
// frame number and time, narrow band of 3 voxels, its zero set moving from
// frame to frame (the vortex carries it) while the enclosed volume stays
// close to the sphere's (the Enright field is divergence-free); each fog
// frame the level set's sdfToFogVolume (1 inside, 0 outside); files named
// NAME.0001.vdb on.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;

namespace {

openvdb::FloatGrid::Ptr readGrid(const fs::path& path) {
    openvdb::io::File file(path.string());
    file.open();
    openvdb::GridPtrVecPtr grids = file.getGrids();
    file.close();
    EXPECT_EQ(grids->size(), 1u) << path;
    return openvdb::gridPtrCast<openvdb::FloatGrid>(grids->at(0));
}

// Voxels of value <= 0 (active or not: the inside's tiles hold -background).
double insideVolume(const openvdb::FloatGrid& grid) {
    uint64_t inside = 0;
    for (auto it = grid.tree().cbeginValueAll(); it; ++it)
        if (*it <= 0) inside += it.getVoxelCount();
    return double(inside) * std::pow(grid.voxelSize()[0], 3);
}

} // namespace

TEST(MakeSequence, FramesAreAnAdvectedLevelSetAndItsFog) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_sequence_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    ASSERT_EQ(vdbdag::testing::runShell(std::string(VDBDAG_SEQUENCE_TOOL) + " " + dir.string() + " --frames 4 --dim 64 >/dev/null").exitCode, 0);
    EXPECT_NE(vdbdag::testing::runShell(std::string(VDBDAG_SEQUENCE_TOOL) + " " + dir.string() + " --frames 0 2>/dev/null").exitCode, 0);
    openvdb::initialize();
    const double sphere = 4.0 / 3.0 * M_PI * std::pow(0.15, 3);
    openvdb::FloatGrid::Ptr previous;
    for (int f = 1; f <= 4; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, ".%04d.vdb", f);
        const openvdb::FloatGrid::Ptr ls = readGrid(dir / ("levelset" + std::string(name)));
        const openvdb::FloatGrid::Ptr fog = readGrid(dir / ("fog" + std::string(name)));
        ASSERT_TRUE(ls && fog) << f;
        EXPECT_EQ(ls->getName(), "surface");
        EXPECT_EQ(ls->getGridClass(), openvdb::GRID_LEVEL_SET);
        EXPECT_EQ(ls->metaValue<int32_t>("frame"), f);
        EXPECT_NEAR(ls->metaValue<float>("time"), 0.05f * float(f - 1), 1e-6f);
        EXPECT_NEAR(ls->background(), 3.0f / 64.0f, 1e-6f);
        EXPECT_NEAR(insideVolume(*ls), sphere, 0.1 * sphere) << "frame " << f;
        EXPECT_EQ(fog->getName(), "density");
        EXPECT_EQ(fog->getGridClass(), openvdb::GRID_FOG_VOLUME);
        float lo = 1, hi = 0;
        for (auto it = fog->tree().cbeginValueOn(); it; ++it) lo = std::min(lo, *it), hi = std::max(hi, *it);
        EXPECT_GE(lo, 0.0f);
        EXPECT_LE(hi, 1.0f);
        if (previous) {  // the surface moved: some voxel near it changed its distance
            double moved = 0;
            auto acc = previous->getConstAccessor();
            for (auto it = ls->tree().cbeginValueOn(); it; ++it) moved = std::max(moved, double(std::abs(*it - acc.getValue(it.getCoord()))));
            EXPECT_GT(moved, 0.1 / 64.0) << "frame " << f;
        }
        previous = ls;
    }
    fs::remove_all(dir);
}

// `encode` of several .vdb frames: each to the folder -o names (made when
// missing), byte for byte what encoding it alone writes; --json an array
// of the reports; -o naming a file is refused and writes nothing.
TEST(MakeSequence, SeveralFramesEncodeOneFileEachAsEachAlone) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_batch_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    ASSERT_EQ(vdbdag::testing::runShell(std::string(VDBDAG_SEQUENCE_TOOL) + " " + (dir / "in").string() + " --frames 3 --dim 48 --no-fog >/dev/null").exitCode, 0);
    std::string inputs;
    for (int f = 1; f <= 3; ++f) inputs += " " + (dir / "in" / ("levelset.000" + std::to_string(f) + ".vdb")).string();
    const vdbdag::testing::CommandResult r = vdbdag::testing::runCli("encode" + inputs + " -o " + (dir / "out").string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json reports = nlohmann::json::parse(r.out);
    ASSERT_TRUE(reports.is_array());
    EXPECT_EQ(reports.size(), 3u);
    for (int f = 1; f <= 3; ++f) {
        const std::string stem = "levelset.000" + std::to_string(f);
        const fs::path alone = dir / (stem + "_alone.ssvdag");
        ASSERT_EQ(vdbdag::testing::runCli("encode " + (dir / "in" / (stem + ".vdb")).string() + " -o " + alone.string()).exitCode, 0);
        EXPECT_EQ(vdbdag::testing::runShell("cmp -s " + alone.string() + " " + (dir / "out" / (stem + ".ssvdag")).string()).exitCode, 0) << stem;
    }
    // -o naming an .ssvdag file: one sequence file of the three frames.
    const fs::path file = dir / "a_file.ssvdag";
    ASSERT_EQ(vdbdag::testing::runCli("encode" + inputs + " -o " + file.string()).exitCode, 0);
    const vdbdag::testing::CommandResult info = vdbdag::testing::runCli("info " + file.string() + " --json");
    ASSERT_EQ(info.exitCode, 0) << info.err;
    EXPECT_EQ(nlohmann::json::parse(info.out)["frames"].size(), 3u);
    // -o naming another file that exists: refused, the file untouched.
    const fs::path other = dir / "notes.txt";
    std::ofstream(other) << "keep";
    const vdbdag::testing::CommandResult refused = vdbdag::testing::runCli("encode" + inputs + " -o " + other.string());
    EXPECT_NE(refused.exitCode, 0);
    EXPECT_NE(refused.err.find("-o names a folder"), std::string::npos) << refused.err;
    EXPECT_EQ(fs::file_size(other), 4u);
    fs::remove_all(dir);
}
