// The `vdbdag` command as a user meets it: exit codes, one-line errors that
// name the file, no partial output left behind, JSON reports that parse and
// agree with OpenVDB's own counts.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <cstring>
#include <fstream>
#include <regex>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/VdbCompare.h"

namespace fs = std::filesystem;

namespace {

using vdbdag::testing::CommandResult;
using vdbdag::testing::runCli;

fs::path workDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_cli_" + std::to_string(getpid()));
        fs::remove_all(d);  // a finished process with the same PID may have left it
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

fs::path sphereFile() {
    const fs::path p = workDir() / "sphere.vdb";
    if (!fs::exists(p)) {
        openvdb::initialize();
        auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(20.0f, openvdb::Vec3f(0.0f), 1.0f, 3.0f);
        g->setName("ball");
        openvdb::io::File f(p.string());
        f.write({g});
        f.close();
    }
    return p;
}

size_t countFiles(const fs::path& dir) {
    size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir)) { (void)e; ++n; }
    return n;
}

} // namespace

TEST(Cli, EncodeDecodeVerifyInfoOnASphere) {
    const fs::path in = sphereFile(), encoded = workDir() / "sphere.ssvdag", decoded = workDir() / "sphere_back.vdb";
    CommandResult r = runCli("encode " + in.string() + " -o " + encoded.string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto report = nlohmann::json::parse(r.out);
    openvdb::io::File f(in.string());
    f.open();
    const uint64_t voxels = f.readGrid("ball")->activeVoxelCount();
    f.close();
    EXPECT_EQ(report["active_voxels"].get<uint64_t>(), voxels);
    EXPECT_EQ(report["bytes"].get<uint64_t>(), fs::file_size(encoded));

    r = runCli("decode " + encoded.string() + " -o " + decoded.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    openvdb::io::File back(decoded.string());
    back.open();
    EXPECT_EQ(back.readGrid("ball")->activeVoxelCount(), voxels);
    back.close();

    r = runCli("verify " + in.string());
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("identical"), std::string::npos);

    r = runCli("info " + encoded.string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto info = nlohmann::json::parse(r.out);
    EXPECT_EQ(info["grids"][0]["name"], "ball");
    EXPECT_EQ(info["grids"][0]["active_voxels"].get<uint64_t>(), voxels);
    // One bits-per-voxel figure per file, encode's; sizes labelled as what they are; versions.
    EXPECT_EQ(info["bits_per_active_voxel"].get<double>(), report["bits_per_active_voxel"].get<double>());
    EXPECT_EQ(info["input_bytes"].get<uint64_t>(), fs::file_size(encoded));
    EXPECT_EQ(info["ssvdag_bytes"].get<uint64_t>(), fs::file_size(encoded));
    EXPECT_EQ(info["tool"], "vdbdag");
    // The file's own container version (the u32 after the magic): 2, a
    // level set whose inside is OpenVDB's signed flood fill (docs/FORMAT.md 3.1).
    const uint32_t fileVersion = [&] {
        std::ifstream f(encoded, std::ios::binary);
        char header[12] = {};
        f.read(header, 12);
        uint32_t v = 0;
        std::memcpy(&v, header + 8, 4);
        return v;
    }();
    EXPECT_EQ(fileVersion, 2u);
    EXPECT_EQ(info["format_version"].get<uint32_t>(), fileVersion);
    const CommandResult text = runCli("info " + encoded.string());
    EXPECT_NE(text.out.find(".ssvdag file (format 2), " + std::to_string(fs::file_size(encoded)) + " bytes"), std::string::npos) << text.out;
    uint64_t sectionBytes = 0;
    for (const auto& s : info["grids"][0]["sections"]) sectionBytes += s["stored_bytes"].get<uint64_t>();
    EXPECT_LT(sectionBytes, fs::file_size(encoded));

    r = runCli("info " + in.string() + " --json");  // .vdb input: all three node counts
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto vdbInfo = nlohmann::json::parse(r.out);
    const auto& leafLevel = vdbInfo["grids"][0]["levels"][0];
    EXPECT_GE(leafLevel["svo_nodes"].get<uint64_t>(), leafLevel["svdag_nodes"].get<uint64_t>());
    EXPECT_GE(leafLevel["svdag_nodes"].get<uint64_t>(), leafLevel["stored_nodes"].get<uint64_t>());
    // The plain SVDAG's counts are a second reduction, stored only on
    // request (`encode --svdag-stats`, issue 41: no hidden pass), and then
    // the counts `info` computes from the .vdb.
    EXPECT_FALSE(info["grids"][0]["levels"][0].contains("svdag_nodes")) << info["grids"][0]["levels"][0].dump();
    const fs::path withStats = workDir() / "ball_stats.ssvdag";
    ASSERT_EQ(runCli("encode " + in.string() + " -o " + withStats.string() + " -f --svdag-stats").exitCode, 0);
    r = runCli("info " + withStats.string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto statsInfo = nlohmann::json::parse(r.out);
    ASSERT_EQ(statsInfo["grids"][0]["levels"].size(), vdbInfo["grids"][0]["levels"].size());
    for (size_t l = 0; l < statsInfo["grids"][0]["levels"].size(); ++l)
        EXPECT_EQ(statsInfo["grids"][0]["levels"][l]["svdag_nodes"], vdbInfo["grids"][0]["levels"][l]["svdag_nodes"]) << l;
}

TEST(Cli, TopologyOnlyEncodingDecodesToAMaskGridWithTheSameVoxels) {
    const fs::path in = sphereFile(), encoded = workDir() / "topo.ssvdag", decoded = workDir() / "topo.vdb";
    ASSERT_EQ(runCli("encode --topology-only " + in.string() + " -o " + encoded.string()).exitCode, 0);
    ASSERT_EQ(runCli("decode " + encoded.string() + " -o " + decoded.string()).exitCode, 0);
    openvdb::io::File original(in.string()), back(decoded.string());
    original.open();
    back.open();
    const auto a = original.readGrid("ball"), b = back.readGrid("ball");
    EXPECT_TRUE(b->isType<openvdb::MaskGrid>());
    EXPECT_EQ(a->activeVoxelCount(), b->activeVoxelCount());
    EXPECT_TRUE(a->transform() == b->transform());
    const CommandResult r = runCli("verify --topology-only " + in.string());
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
}

TEST(Cli, ComparisonUsedByVerifyFindsARemovedVoxelAndAnAddedTile) {
    openvdb::initialize();
    const fs::path a = workDir() / "a.vdb", b = workDir() / "b.vdb", c = workDir() / "c.vdb";
    auto g = openvdb::FloatGrid::create();
    g->setName("g");
    g->tree().setValueOn(openvdb::Coord(1, 2, 3), 1.0f);
    g->tree().setValueOn(openvdb::Coord(100, 2, 3), 1.0f);
    openvdb::io::File(a.string()).write({g});
    auto withoutVoxel = g->deepCopy();
    withoutVoxel->tree().setValueOff(openvdb::Coord(100, 2, 3));
    openvdb::io::File(b.string()).write({withoutVoxel});
    auto withTile = g->deepCopy();
    withTile->tree().addTile(1, openvdb::Coord(800, 0, 0), 1.0f, true);
    openvdb::io::File(c.string()).write({withTile});

    const auto removed = vdbdag::bridge::compareFiles(a.string(), b.string());
    EXPECT_FALSE(removed.identical);
    ASSERT_EQ(removed.topology.size(), 1u);
    EXPECT_EQ(removed.topology[0].onlyInA, 1u);
    EXPECT_EQ(removed.topology[0].onlyInB, 0u);
    ASSERT_FALSE(removed.topology[0].examples.empty());
    EXPECT_NE(removed.topology[0].examples[0].find("(100,2,3)"), std::string::npos) << removed.topology[0].examples[0];

    const auto added = vdbdag::bridge::compareFiles(a.string(), c.string());
    ASSERT_EQ(added.topology.size(), 1u);
    EXPECT_EQ(added.topology[0].onlyInB, 512u);
    EXPECT_TRUE(vdbdag::bridge::compareFiles(a.string(), a.string()).identical);
}

TEST(Cli, BadInputsGiveOneLineErrorsAndLeaveNoOutput) {
    const fs::path dir = workDir() / "bad";
    fs::create_directories(dir);
    const size_t before = countFiles(dir);
    struct Case { std::string args, mustMention; };
    // A truncated and a corrupted .ssvdag.
    const fs::path good = workDir() / "good.ssvdag";
    ASSERT_EQ(runCli("encode " + sphereFile().string() + " -o " + good.string()).exitCode, 0);
    std::ifstream in(good, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    const fs::path truncated = workDir() / "truncated.ssvdag", corrupted = workDir() / "corrupted.ssvdag", text = workDir() / "text.vdb";
    std::ofstream(truncated, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() / 2));
    bytes[bytes.size() - 10] ^= 0x55;
    std::ofstream(corrupted, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    std::ofstream(text) << "this is not a vdb file\n";
    const std::vector<Case> cases = {
        {"encode /nonexistent/in.vdb -o " + (dir / "x.ssvdag").string(), "/nonexistent/in.vdb"},
        {"encode " + text.string() + " -o " + (dir / "x.ssvdag").string(), text.string()},
        {"decode " + truncated.string() + " -o " + (dir / "x.vdb").string(), "truncated"},
        {"decode " + corrupted.string() + " -o " + (dir / "x.vdb").string(), "corrupted"},
        {"decode " + sphereFile().string() + " -o " + (dir / "x.vdb").string(), "not an .ssvdag file"},
        {"info " + truncated.string(), "truncated"},
        {"encode " + sphereFile().string() + " -o /nonexistent/dir/x.ssvdag", "does not exist"},
        {"encode " + sphereFile().string() + " --grid nope -o " + (dir / "x.ssvdag").string(), "no grid named 'nope'"},
    };
    for (const Case& c : cases) {
        const CommandResult r = runCli(c.args);
        EXPECT_NE(r.exitCode, 0) << c.args;
        EXPECT_NE(r.err.find(c.mustMention), std::string::npos) << c.args << " -> " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << " -> " << r.err;
    }
    EXPECT_EQ(countFiles(dir), before) << "a failed command left output behind";
    const fs::path points = fs::path(VDBDAG_SHARED_DATA) / "vdb" / "points.vdb";
    if (fs::exists(points)) {
        const CommandResult r = runCli("encode " + points.string() + " -o " + (dir / "p.ssvdag").string());
        EXPECT_NE(r.exitCode, 0);
        EXPECT_NE(r.err.find("PointDataGrid"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir / "p.ssvdag"));
    }
}

TEST(Cli, RenderOnVulkanAndCpuGivesTheSamePngAndAutoFallsBackWithoutADevice) {
    const fs::path encoded = workDir() / "render_ball.ssvdag";
    ASSERT_EQ(runCli("encode " + sphereFile().string() + " -o " + encoded.string()).exitCode, 0);
    const fs::path cpuPng = workDir() / "ball_cpu.png", vulkanPng = workDir() / "ball_vulkan.png";
    CommandResult r = runCli("render " + encoded.string() + " -o " + cpuPng.string() + " --backend cpu --width 96 --height 64 --shadows --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["backend"], "cpu");
    EXPECT_EQ(report["primary_rays"], 96 * 64);
    // No driver: auto renders on the CPU with a one-line note; --backend vulkan is a one-line error and writes nothing.
    const std::string noDriver = "env -u VK_ADD_DRIVER_FILES -u VDBDAG_VULKAN_VALIDATION VK_ICD_FILENAMES=/nonexistent/vdbdag_icd.json "
                                 "VK_DRIVER_FILES=/nonexistent/vdbdag_icd.json ";
    const fs::path fallbackPng = workDir() / "ball_fallback.png";
    r = runCli("render " + encoded.string() + " -o " + fallbackPng.string() + " --width 96 --height 64 --json", noDriver);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["backend"], "cpu");
    EXPECT_TRUE(r.err.starts_with("vdbdag: note: no Vulkan device")) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    // --quiet (before or after the command's name) drops the note, not the result.
    for (const char* quiet : {"-q render ", "render --quiet "}) {
        r = runCli(std::string(quiet) + encoded.string() + " -o " + fallbackPng.string() + " -f --width 96 --height 64 --json", noDriver);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        EXPECT_EQ(nlohmann::json::parse(r.out)["backend"], "cpu");
        EXPECT_EQ(r.err, "") << quiet;
    }
    r = runCli("render " + encoded.string() + " -o " + vulkanPng.string() + " --backend vulkan", noDriver);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_TRUE(r.err.starts_with("vdbdag: no Vulkan device found")) << r.err;
    EXPECT_FALSE(fs::exists(vulkanPng));
    // With the device (when there is one): the same pixels, so the same PNG bytes.
    r = runCli("render " + encoded.string() + " -o " + vulkanPng.string() + " --backend vulkan --width 96 --height 64 --shadows --json");
    if (r.exitCode != 0 && r.err.find("no Vulkan device") != std::string::npos) GTEST_SKIP() << "no Vulkan device on this machine";
    ASSERT_EQ(r.exitCode, 0) << r.err;
    report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["backend"], "vulkan");
    {  // the device that ran it, as `vdbdag devices --json` names its default
        const CommandResult devices = runCli("devices --json");
        ASSERT_EQ(devices.exitCode, 0) << devices.err;
        const std::string listed = devices.out;
        const std::string device = report["device"].get<std::string>();
        EXPECT_FALSE(device.empty());
        EXPECT_NE(listed.find(device), std::string::npos) << device << " not in " << listed;
    }
    EXPECT_GT(report["secondary_rays"].get<int>(), 0);
    auto slurp = [](const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    EXPECT_FALSE(slurp(cpuPng).empty());
    EXPECT_EQ(slurp(cpuPng), slurp(vulkanPng)) << "the Vulkan and CPU renders differ";
    r = runCli("render " + encoded.string() + " -o " + vulkanPng.string() + " --backend vulkan --device 99");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// `encode --normals 10`: both backends shade with the stored ONV normals, so
// the PNGs are the same bytes, and differ from the render without normals.
TEST(Cli, RenderWithOnvNormalsOnVulkanAndCpuGivesTheSamePng) {
    const fs::path plain = workDir() / "onv_ball_plain.ssvdag", withNormals = workDir() / "onv_ball_10.ssvdag";
    ASSERT_EQ(runCli("encode " + sphereFile().string() + " -o " + plain.string()).exitCode, 0);
    ASSERT_EQ(runCli("encode " + sphereFile().string() + " --normals 10 -o " + withNormals.string()).exitCode, 0);
    const std::string size = " --width 96 --height 64";
    const fs::path plainPng = workDir() / "onv_ball_plain.png", cpuPng = workDir() / "onv_ball_cpu.png", vulkanPng = workDir() / "onv_ball_vulkan.png";
    ASSERT_EQ(runCli("render " + plain.string() + " -o " + plainPng.string() + " --backend cpu" + size).exitCode, 0);
    ASSERT_EQ(runCli("render " + withNormals.string() + " -o " + cpuPng.string() + " --backend cpu" + size).exitCode, 0);
    const CommandResult r = runCli("render " + withNormals.string() + " -o " + vulkanPng.string() + " --backend vulkan" + size);
    if (r.exitCode != 0 && r.err.find("no Vulkan device") != std::string::npos) GTEST_SKIP() << "no Vulkan device on this machine";
    ASSERT_EQ(r.exitCode, 0) << r.err;
    auto slurp = [](const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    EXPECT_FALSE(slurp(cpuPng).empty());
    EXPECT_EQ(slurp(cpuPng), slurp(vulkanPng)) << "the Vulkan and CPU renders with ONV normals differ";
    EXPECT_NE(slurp(cpuPng), slurp(plainPng)) << "the stored normals changed nothing";
}

// --max-voxels and --max-memory on every command that expands a file: a
// one-line error naming the file and the limit, exit 1, nothing written.
// The ball's entries (active voxels, a closed form of OpenVDB's count here)
// are the threshold: one less is refused, the count itself passes. (`info`
// without --values expands nothing of a file with Summary sections: it
// reads the headers, test_summary_section.cpp.)
TEST(Cli, ReadLimitsRefuseAFileBeforeExpandingIt) {
    const fs::path encoded = workDir() / "limits_ball.ssvdag";
    ASSERT_EQ(runCli("encode " + sphereFile().string() + " -o " + encoded.string()).exitCode, 0);
    openvdb::io::File file(sphereFile().string());
    file.open();
    const uint64_t active = file.readGrid("ball")->activeVoxelCount();
    file.close();
    const fs::path dir = workDir() / "limits";
    fs::create_directories(dir);
    const std::string in = encoded.string();
    const std::vector<std::string> commands{"decode " + in + " -o " + (dir / "o.vdb").string(), "export " + in + " -o " + (dir / "o.vtu").string(),
                                            "render " + in + " -o " + (dir / "o.png").string() + " --backend cpu --width 8 --height 8",
                                            "info " + in + " --values", "verify " + sphereFile().string() + " --encoded " + in,
                                            "diff " + in + " " + sphereFile().string()};
    for (const std::string& c : commands) {
        for (const std::string& limit : {"--max-voxels " + std::to_string(active - 1), std::string("--max-memory 2K")}) {
            const CommandResult r = runCli(c + " " + limit);
            EXPECT_EQ(r.exitCode, c.rfind("diff", 0) == 0 ? 2 : 1) << c << " " << limit;  // diff: 1 means "they differ"
            EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
            EXPECT_NE(r.err.find(in), std::string::npos) << r.err;
            EXPECT_NE(r.err.find(limit.substr(0, limit.find(' '))), std::string::npos) << r.err;
            EXPECT_TRUE(fs::is_empty(dir)) << c << " " << limit << " left output";
        }
        const CommandResult ok = runCli(c + " --max-voxels " + std::to_string(active));
        EXPECT_EQ(ok.exitCode, 0) << c << "\n" << ok.err;
        for (const auto& e : fs::directory_iterator(dir)) fs::remove(e.path());
    }
}

// Mistakes in the command line itself: one line naming the word and what
// was probably meant, exit status 2; `help` is a command; diff keeps 1 for
// "they differ" and answers 2 for a failure.
TEST(Cli, UsageMistakesAreOneLineWithASuggestionAndExitTwo) {
    struct Case {
        std::string args, expect;
    };
    const std::string ball = sphereFile().string();
    for (const Case& c : std::vector<Case>{{"encod " + ball, "'encod' is not a command; did you mean 'encode'?"},
                                            {"", "a command is required"},
                                            {"encode " + ball + " -o x.ssvdag --abs-eror 0.1", "unknown option '--abs-eror'; did you mean '--abs-error'?"},
                                            {"render x.ssvdag -o x.png --widht=8", "unknown option '--widht'; did you mean '--width'?"},
                                            {"render x.ssvdag -o x.png --view fornt", "--view: 'fornt' is not one of iso, front, back, side, top; did you mean 'front'?"},
                                            {"help encdoe", "'encdoe' is not a command; did you mean 'encode'?"},
                                            // sizes (issue 38: -1, 0 and 23 digits were taken)
                                            {"encode " + ball + " -o x.ssvdag --memory-limit -1", "'-1' is not a size"},
                                            {"encode " + ball + " -o x.ssvdag --memory-limit 0", "0 is not a size"},
                                            {"verify " + ball + " --memory-limit 12345678901234567890123", "at most 2^60 bytes"},
                                            {"decode x.ssvdag -o x.vdb --max-memory 2X", "units: K, M, G, T"}}) {
        const CommandResult r = runCli(c.args);
        EXPECT_EQ(r.exitCode, 2) << c.args << "\n" << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << "\n" << r.err;
        EXPECT_TRUE(r.out.empty()) << r.out;
    }
    CommandResult r = runCli("help");
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_NE(r.out.find("Exit status"), std::string::npos) << r.out;
    r = runCli("help encode");
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_NE(r.out.find("--memory-limit"), std::string::npos) << r.out;
    EXPECT_EQ(runCli("encode --help").out, r.out);

    const fs::path other = workDir() / "usage_other.vdb";
    {
        openvdb::initialize();
        auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(21.0f, openvdb::Vec3f(0.0f), 1.0f, 3.0f);
        g->setName("ball");
        openvdb::io::File(other.string()).write({g});
    }
    EXPECT_EQ(runCli("diff " + ball + " " + ball).exitCode, 0);
    EXPECT_EQ(runCli("diff " + ball + " " + other.string()).exitCode, 1);
    r = runCli("diff " + ball + " " + (workDir() / "missing.vdb").string());
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("missing.vdb"), std::string::npos) << r.err;
}

// A suggestion only when one name is close: a typo ("verif"), never a guess
// for a word like no command at all.
TEST(Cli, UnknownCommandsGetASuggestionOnlyWhenOneIsClose) {
    const CommandResult r = runCli("verif x");
    EXPECT_NE(r.err.find("did you mean 'verify'?"), std::string::npos) << r.err;
    const CommandResult none = runCli("frobnicate x");
    EXPECT_EQ(none.err.find("did you mean"), std::string::npos) << none.err;
    EXPECT_EQ(none.exitCode, 2);
}

// A .vdb whose transform OpenVDB reads but cannot use (its scale forged to
// zero in the file's bytes): every command that reads it names the file and
// the grid, in one line, instead of OpenVDB's bare "ArithmeticError".
TEST(Cli, AnUnusableTransformIsAnErrorNamingTheFile) {
    const fs::path good = workDir() / "zero_scale_src.vdb", bad = workDir() / "zero_scale.vdb";
    {
        openvdb::initialize();
        auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(20.0f, openvdb::Vec3f(0.0f), 0.5f, 3.0f);
        g->setName("ball");
        openvdb::io::File(good.string()).write({g});
    }
    std::ifstream in(good, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    const std::string map = "UniformScaleMap";
    const size_t at = bytes.find(map);
    ASSERT_NE(at, std::string::npos) << "OpenVDB wrote another map type";
    double scale = 0;
    std::memcpy(&scale, bytes.data() + at + map.size(), 8);
    ASSERT_DOUBLE_EQ(scale, 0.5) << "not the scale where expected";
    std::fill(bytes.begin() + long(at + map.size()), bytes.begin() + long(at + map.size() + 48), '\0');  // scale and voxel size
    std::ofstream(bad, std::ios::binary) << bytes;
    const std::string f = bad.string(), out = (workDir() / "zero_scale_out").string();
    for (const std::string& c : {"info " + f, "encode " + f + " -o " + out + ".ssvdag", "encode " + f + " -o " + out + ".ssvdag --memory-limit 64M",
                                 "export " + f + " -o " + out + ".vtu", "verify " + f}) {
        const CommandResult r = runCli(c);
        EXPECT_EQ(r.exitCode, 1) << c;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_NE(r.err.find(f + ": grid 0 'ball' has an unusable transform"), std::string::npos) << c << "\n" << r.err;
    }
    EXPECT_FALSE(fs::exists(out + ".ssvdag"));
    EXPECT_FALSE(fs::exists(out + ".vtu"));
}

// Options every command takes, before or after its name: --threads N (the
// same output), -v (a last line with time and peak memory), and their
// mistakes as usage errors (exit 2).
TEST(Cli, GlobalOptionsWorkBeforeAndAfterTheCommand) {
    const fs::path in = sphereFile(), encoded = workDir() / "global.ssvdag", one = workDir() / "global_1.vdb", all = workDir() / "global_n.vdb";
    ASSERT_EQ(runCli("--threads 1 encode " + in.string() + " -o " + encoded.string()).exitCode, 0);
    ASSERT_EQ(runCli("decode " + encoded.string() + " -o " + one.string() + " --threads 1").exitCode, 0);
    ASSERT_EQ(runCli("decode " + encoded.string() + " -o " + all.string()).exitCode, 0);
    auto bytesOf = [](const fs::path& p) {
        std::ifstream f(p, std::ios::binary);
        std::string s{std::istreambuf_iterator<char>(f), {}};
        if (s.size() > 57) s.replace(21, 36, 36, '0');  // the random file UUID OpenVDB writes after the 21-byte header
        return s;
    };
    EXPECT_EQ(bytesOf(one), bytesOf(all)) << "--threads changed the decoded file";
    for (const std::string& args : {"-v info " + encoded.string(), "info " + encoded.string() + " --verbose"}) {
        const CommandResult r = runCli(args);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        EXPECT_TRUE(r.err.starts_with("vdbdag: info took ")) << args << ": " << r.err;
        EXPECT_NE(r.err.find("peak resident memory"), std::string::npos) << r.err;
    }
    EXPECT_EQ(runCli("--threads 0 info " + encoded.string()).exitCode, 2);
    EXPECT_EQ(runCli("info " + encoded.string() + " --threads x").exitCode, 2);
}

// Every command's JSON report parses, carries the tool and format versions,
// and names its input the same way ("input"; "inputs" for diff) and the
// .ssvdag's size as "ssvdag_bytes" (the size of the file on disk).
TEST(Cli, EveryJsonReportCarriesTheVersionsAndTheCommonKeys) {
    const fs::path in = sphereFile(), ss = workDir() / "keys.ssvdag", vtu = workDir() / "keys.vtu", png = workDir() / "keys.png";
    const std::string i = in.string(), s = ss.string();
    const std::vector<std::pair<std::string, std::string>> commands{
        {"encode " + i + " -o " + s + " -f --json", "input"},
        {"info " + s + " --json", "input"},
        {"info " + i + " --json", "input"},
        {"verify " + i + " --json", "input"},
        {"render " + s + " -o " + png.string() + " -f --backend cpu --width 16 --height 16 --json", "input"},
        {"export " + s + " -o " + vtu.string() + " -f --json", "input"},
        {"diff " + i + " " + s + " --json", "inputs"},
    };
    for (const auto& [args, inputKey] : commands) {
        const CommandResult r = runCli(args);
        ASSERT_EQ(r.exitCode, 0) << args << ": " << r.err;
        const nlohmann::json j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j["tool"], "vdbdag") << args;
        EXPECT_TRUE(j["tool_version"].is_string()) << args;
        // An .ssvdag's report gives its file's version (this level set's: 2), the others the version the tool writes by default.
        EXPECT_EQ(j["format_version"].get<uint32_t>(), args.starts_with("info " + s) ? 2u : 1u) << args;
        EXPECT_TRUE(j.contains(inputKey)) << args;
        if (j.contains("ssvdag_bytes") && (args.starts_with("encode") || args.starts_with("info " + s))) {
            EXPECT_EQ(j["ssvdag_bytes"].get<uint64_t>(), fs::file_size(ss)) << args;
        }
    }
    const CommandResult version = runCli("--version");
    const CommandResult info = runCli("info " + s + " --json");
    EXPECT_EQ(version.out, "vdbdag " + nlohmann::json::parse(info.out)["tool_version"].get<std::string>() + "\n");
}

namespace {

// A fog sphere (OpenVDB's level set turned into densities) with `cls` as its class.
fs::path fogSphere(const std::string& name, openvdb::GridClass cls) {
    const fs::path p = workDir() / (name + ".vdb");
    openvdb::initialize();
    auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(16.0f, openvdb::Vec3f(0.0f), 1.0f, 3.0f);
    openvdb::tools::sdfToFogVolume(*g);
    g->setName("density");
    g->setGridClass(cls);
    openvdb::io::File f(p.string());
    f.write({g});
    f.close();
    return p;
}

std::string fileBytes(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), {}};
}

} // namespace

// A fog whose class is "unknown" (as nanovdb_convert writes it) is shown as
// fog, like the same grid of class "fog volume": the same picture; options
// that would have no effect are refused.
TEST(Cli, AFogOfUnknownClassRendersAsFogAndEveryRenderOptionTakesEffect) {
    const fs::path fog = fogSphere("fog_class", openvdb::GRID_FOG_VOLUME), unknown = fogSphere("fog_unknown", openvdb::GRID_UNKNOWN);
    const fs::path a = workDir() / "fog_class.ssvdag", b = workDir() / "fog_unknown.ssvdag";
    ASSERT_EQ(runCli("encode " + fog.string() + " -o " + a.string()).exitCode, 0);
    ASSERT_EQ(runCli("encode " + unknown.string() + " -o " + b.string()).exitCode, 0);
    const fs::path pa = workDir() / "fog_class.png", pb = workDir() / "fog_unknown.png", pv = workDir() / "fog_values.png";
    const std::string size = " --backend cpu --width 48 --height 40 --json";
    CommandResult r = runCli("render " + a.string() + " -o " + pa.string() + size);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["shading"], "fog");
    r = runCli("render " + b.string() + " -o " + pb.string() + size);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["shading"], "fog");
    EXPECT_EQ(fileBytes(pa), fileBytes(pb)) << "the class-unknown fog must render as the fog volume does";
    // --density-scale takes effect on a fog (the default is chosen from the view).
    const fs::path ps = workDir() / "fog_scaled.png";
    r = runCli("render " + b.string() + " -o " + ps.string() + size + " --density-scale 0.5");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["density_scale"].get<double>(), 0.5);
    EXPECT_NE(fileBytes(ps), fileBytes(pb));
    r = runCli("render " + b.string() + " -o " + pv.string() + size + " --shading values");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["shading"], "values");
    EXPECT_NE(fileBytes(pv), fileBytes(pb));
    // A level set is a surface: --density-scale has no effect there and is refused, in one line.
    const fs::path ls = sphereFile(), lss = workDir() / "ls_render.ssvdag";
    ASSERT_EQ(runCli("encode " + ls.string() + " -o " + lss.string() + " -f").exitCode, 0);
    r = runCli("render " + lss.string() + " -o " + (workDir() / "ls_ds.png").string() + size + " --density-scale 0.5");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("--density-scale applies to fog shading"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(workDir() / "ls_ds.png"));
    // --camera and --view together: refused.
    r = runCli("render " + lss.string() + " -o " + (workDir() / "ls_cv.png").string() + size + " --view top --camera 0,0,90,0,0,0,0,1,0");
    EXPECT_EQ(r.exitCode, 1) << r.err;
}

// --up and --view place the default camera: its up is the world axis asked
// for, and it looks along the documented axis at the middle of the grid.
TEST(Cli, UpAndViewPlaceTheDefaultCamera) {
    const fs::path ls = sphereFile(), ss = workDir() / "views.ssvdag";
    ASSERT_EQ(runCli("encode " + ls.string() + " -o " + ss.string() + " -f").exitCode, 0);
    struct Case {
        std::string args;
        std::array<double, 3> up, from;  // from: unit direction target -> eye
    };
    for (const Case& c : {Case{"--up z --view front", {0, 0, 1}, {0, -1, 0}}, Case{"--up z --view side", {0, 0, 1}, {1, 0, 0}},
                          Case{"--up z --view top", {0, 1, 0}, {0, 0, 1}}, Case{"--view front", {0, 1, 0}, {0, 0, 1}},
                          Case{"--view back", {0, 1, 0}, {0, 0, -1}}, Case{"--up z --view back", {0, 0, 1}, {0, 1, 0}},
                          Case{"--up x --view side", {1, 0, 0}, {0, 1, 0}}}) {
        const CommandResult r = runCli("render " + ss.string() + " -o " + (workDir() / "view.png").string() + " -f --backend cpu --width 16 --height 16 --json " + c.args);
        ASSERT_EQ(r.exitCode, 0) << c.args << ": " << r.err;
        const auto cam = nlohmann::json::parse(r.out)["camera"];
        std::array<double, 3> d{};
        double len = 0;
        for (int i = 0; i < 3; ++i) {
            d[i] = cam["eye"][i].get<double>() - cam["target"][i].get<double>();
            len += d[i] * d[i];
        }
        for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(cam["up"][i].get<double>(), c.up[i], 1e-12) << c.args;
            EXPECT_NEAR(d[i] / std::sqrt(len), c.from[i], 1e-12) << c.args;
        }
    }
}

// The man page the build writes (help2man, when installed) describes every
// command, the global options and the exit status.
TEST(Cli, TheManPageDescribesEveryCommand) {
    const fs::path page = fs::path(VDBDAG_BINARY).parent_path() / "vdbdag.1";
    if (!fs::exists(page)) GTEST_SKIP() << "no man page: help2man is not installed";
    const std::string text = fileBytes(page);
    for (const char* c : {"encode", "decode", "info", "verify", "render", "devices", "export", "diff", "import", "bench", "selftest"})
        EXPECT_NE(text.find(std::string(".SS ") + c + "\n"), std::string::npos) << c;
    for (const char* s : {"EXIT STATUS", "quiet", "threads", "--memory-limit"})
        EXPECT_NE(text.find(s), std::string::npos) << s;
}

// Each command's --help ends with an example of its use, and shows defaults.
TEST(Cli, EveryCommandsHelpShowsAnExampleAndItsDefaults) {
    for (const char* c : {"encode", "decode", "info", "verify", "render", "devices", "export", "diff", "import", "bench", "selftest"}) {
        const CommandResult r = runCli(std::string(c) + " --help");
        ASSERT_EQ(r.exitCode, 0) << c;
        const size_t at = r.out.find("Example:\n  vdbdag " + std::string(c) + " ");
        EXPECT_NE(at, std::string::npos) << c << ":\n" << r.out;
    }
    const CommandResult render = runCli("render --help");
    EXPECT_NE(render.out.find("--width INT:INT in [1 - 16384]=1024"), std::string::npos) << render.out;
    EXPECT_NE(render.out.find("--view TEXT:{iso,front,back,side,top}=iso"), std::string::npos) << render.out;
}

// Every environment variable the product's sources read (std::getenv in
// src/, app/, vdb_bridge/, gpu/, cli/, found by reading them) is named in
// `vdbdag --help`: no behaviour hides behind one (issue 41 #2).
TEST(Cli, EveryEnvironmentVariableReadIsInTheHelp) {
    const CommandResult help = runCli("--help");
    ASSERT_EQ(help.exitCode, 0);
    const std::regex read(R"re(getenv\(\s*"([A-Z0-9_]+)"\s*\))re");
    size_t names = 0;
    for (const char* folder : {"src", "app", "vdb_bridge", "gpu", "cli"})
        for (const auto& e : fs::recursive_directory_iterator(fs::path(VDBDAG_SOURCE_DIR) / folder)) {
            if (!e.is_regular_file() || e.path().string().find("selftest") != std::string::npos) continue;
            const std::string text = fileBytes(e.path());
            for (auto m = std::sregex_iterator(text.begin(), text.end(), read); m != std::sregex_iterator(); ++m, ++names)
                EXPECT_NE(help.out.find((*m)[1].str()), std::string::npos) << (*m)[1].str() << " (read in " << e.path() << ") is not in vdbdag --help";
        }
    EXPECT_GE(names, 1u) << "the search found no getenv at all: the pattern is wrong";
    EXPECT_NE(runCli("render --help").out.find("VDBDAG_VULKAN_VALIDATION"), std::string::npos);
}

// Without -o, encode writes IN.ssvdag beside the input (the name without its
// extension; .nii.gz counts as one), and like any new output it never
// replaces a file there without --force (issue 42 #4).
TEST(Cli, EncodeWithoutAnOutputWritesBesideTheInput) {
    const fs::path dir = workDir() / "default_name";
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(sphereFile(), dir / "ball.vdb");
    CommandResult r = runCli("encode " + (dir / "ball.vdb").string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "ball.ssvdag"));
    EXPECT_NE(r.out.find((dir / "ball.ssvdag").string()), std::string::npos) << r.out;
    r = runCli("encode " + (dir / "ball.vdb").string());
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("already exists"), std::string::npos) << r.err;
    {
        std::ofstream raw(dir / "ct_4x4x4_uint8.raw", std::ios::binary);
        raw << std::string(64, '\3');
    }
    r = runCli("encode " + (dir / "ct_4x4x4_uint8.raw").string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "ct_4x4x4_uint8.ssvdag"));
    fs::remove_all(dir);
}

// decode says what it wrote (a line, or --json), and export's --max-bytes
// takes a size with its unit as the other size options do (issue 42 #4).
TEST(Cli, DecodeReportsWhatItWroteAndSizesTakeUnits) {
    const fs::path encoded = workDir() / "report_ball.ssvdag", back = workDir() / "report_ball.vdb";
    ASSERT_EQ(runCli("encode " + sphereFile().string() + " -o " + encoded.string() + " -f").exitCode, 0);
    CommandResult r = runCli("decode " + encoded.string() + " -o " + back.string() + " -f --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["output_bytes"].get<uint64_t>(), fs::file_size(back));
    openvdb::initialize();
    openvdb::io::File file(back.string());
    file.open();
    uint64_t active = 0;
    const openvdb::GridPtrVecPtr grids = file.getGrids();
    for (const auto& g : *grids) active += g->activeVoxelCount();
    file.close();
    EXPECT_EQ(report["active_voxels"].get<uint64_t>(), active);
    r = runCli("decode " + encoded.string() + " -o " + back.string() + " -f");
    EXPECT_NE(r.out.find(back.string()), std::string::npos) << r.out;
    r = runCli("export " + encoded.string() + " -o " + (workDir() / "report_ball.vti").string() + " -f --max-bytes 600M");
    EXPECT_EQ(r.exitCode, 0) << r.err;
}


// Every render option takes effect or is refused: --shadows on a fog (it
// was silently ignored: 0 shadow rays); the default fog density scale is
// reported (issue 42 #2).
TEST(Cli, ShadowsOnAFogAreRefusedAndTheFogScaleIsReported) {
    const fs::path fog = fs::path(VDBDAG_SOURCE_DIR) / "tests" / "golden" / "fog.vdb", encoded = workDir() / "fog_shadows.ssvdag";
    ASSERT_EQ(runCli("encode " + fog.string() + " -o " + encoded.string() + " -f").exitCode, 0);
    const fs::path png = workDir() / "fog_shadows.png";
    CommandResult r = runCli("render " + encoded.string() + " -o " + png.string() + " -f --backend cpu --width 16 --height 16 --shadows");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("no shadows"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(png));
    r = runCli("render " + encoded.string() + " -o " + png.string() + " -f --backend cpu --width 16 --height 16 --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["shading"], "fog");
    EXPECT_GT(j["density_scale"].get<double>(), 0.0);
}
