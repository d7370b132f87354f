// Every readable input everywhere (issue 42 #4): `render` takes a .vdb, a
// .nvdb or a scan (encoded in memory, vdb_bridge/InputScene.h) and draws
// the same picture as for the .ssvdag `encode` writes; `info`, `diff` and
// `verify` take a NanoVDB file, read through NanoVDB, against OpenVDB's own
// counts.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;
using vdbdag::testing::CommandResult;
using vdbdag::testing::runCli;

namespace {

fs::path workDir() {
    const fs::path d = fs::temp_directory_path() / ("vdbdag_any_input_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

std::string bytesOf(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

const fs::path kLevelSet = fs::path(VDBDAG_SOURCE_DIR) / "tests" / "golden" / "levelset.vdb";

} // namespace

TEST(AnyInput, RenderOfAVdbIsTheRenderOfItsSsvdag) {
    const fs::path ss = workDir() / "ls.ssvdag", a = workDir() / "from_vdb.png", b = workDir() / "from_ssvdag.png";
    ASSERT_EQ(runCli("encode " + kLevelSet.string() + " -o " + ss.string() + " -f").exitCode, 0);
    const std::string size = " -f --backend cpu --width 48 --height 40";
    CommandResult r = runCli("render " + kLevelSet.string() + " -o " + a.string() + size);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = runCli("render " + ss.string() + " -o " + b.string() + size);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_FALSE(bytesOf(a).empty());
    EXPECT_EQ(bytesOf(a), bytesOf(b));
    // A scan too (a raw volume by its name).
    const fs::path raw = workDir() / "scan_8x8x8_uint8.raw";
    std::ofstream(raw, std::ios::binary) << std::string(512, '\x7');
    r = runCli("render " + raw.string() + " -o " + (workDir() / "scan.png").string() + size);
    EXPECT_EQ(r.exitCode, 0) << r.err;
}

TEST(AnyInput, InfoDiffAndVerifyTakeANanoVdbFile) {
    const fs::path ss = workDir() / "ls_nano.ssvdag", nano = workDir() / "ls.nvdb";
    ASSERT_EQ(runCli("encode " + kLevelSet.string() + " -o " + ss.string() + " -f").exitCode, 0);
    ASSERT_EQ(runCli("decode " + ss.string() + " -o " + nano.string() + " -f").exitCode, 0);
    openvdb::initialize();
    openvdb::io::File file(kLevelSet.string());
    file.open();
    const openvdb::GridPtrVecPtr grids = file.getGrids();
    file.close();
    CommandResult r = runCli("info " + nano.string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json info = nlohmann::json::parse(r.out);
    EXPECT_EQ(info["format"], "nvdb");
    ASSERT_EQ(info["grids"].size(), grids->size());
    for (size_t g = 0; g < grids->size(); ++g) {
        EXPECT_EQ(info["grids"][g]["name"], (*grids)[g]->getName());
        EXPECT_EQ(info["grids"][g]["active_voxels"].get<uint64_t>(), (*grids)[g]->activeVoxelCount());
    }
    r = runCli("diff " + nano.string() + " " + kLevelSet.string() + " --json");
    EXPECT_EQ(r.exitCode, 0) << r.err << r.out;
    EXPECT_TRUE(nlohmann::json::parse(r.out)["identical"].get<bool>());
    // verify: its grids, as NanoVDB reads them, survive the round trip; no temporary is left.
    const fs::path scratch = workDir() / "scratch";
    fs::create_directories(scratch);
    r = runCli("verify " + nano.string() + " --json --scratch " + scratch.string());
    EXPECT_EQ(r.exitCode, 0) << r.err << r.out;
    EXPECT_TRUE(nlohmann::json::parse(r.out)["identical"].get<bool>());
    EXPECT_TRUE(fs::is_empty(scratch));
    fs::remove_all(workDir());
}

// `info a.vdb b.nvdb c.ssvdag` describes each (issue 42 #4; it was refused):
// the text one after the other, --json an array in the order given, each
// with OpenVDB's active voxel count of its source.
TEST(AnyInput, InfoDescribesSeveralFilesInTurn) {
    const fs::path fog = fs::path(VDBDAG_SOURCE_DIR) / "tests" / "golden" / "fog.vdb", ss = workDir() / "several.ssvdag";
    ASSERT_EQ(runCli("encode " + fog.string() + " -o " + ss.string() + " -f").exitCode, 0);
    const CommandResult r = runCli("info " + kLevelSet.string() + " " + ss.string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json all = nlohmann::json::parse(r.out);
    ASSERT_TRUE(all.is_array());
    ASSERT_EQ(all.size(), 2u);
    EXPECT_EQ(all[0]["format"], "vdb");
    EXPECT_EQ(all[1]["format"], "ssvdag");
    openvdb::initialize();
    for (const auto& [index, path] : {std::pair{0, kLevelSet}, std::pair{1, fog}}) {
        openvdb::io::File file(path.string());
        file.open();
        const openvdb::GridPtrVecPtr grids = file.getGrids();
        file.close();
        EXPECT_EQ(all[size_t(index)]["grids"][0]["active_voxels"].get<uint64_t>(), (*grids)[0]->activeVoxelCount()) << path;
    }
    const CommandResult text = runCli("info " + kLevelSet.string() + " " + ss.string());
    EXPECT_NE(text.out.find(kLevelSet.string() + ": OpenVDB file"), std::string::npos) << text.out;
    EXPECT_NE(text.out.find(ss.string() + ": .ssvdag file"), std::string::npos) << text.out;
    fs::remove_all(workDir());
}
