// `vdbdag encode --colour-bits / --normals` and `info` as a user meets them:
// the reports (text and --json) show the colour and normal errors stored in
// the file, bad option values give one-line errors and leave no output.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;

namespace {

using CliRun = vdbdag::testing::CommandResult;
inline CliRun run(const std::string& args) { return vdbdag::testing::runCli(args); }

// A level set "ball" and a random vec3s colour grid "Cd" (8,000 colours).
fs::path inputFile(const fs::path& dir) {
    openvdb::initialize();
    const fs::path p = dir / "scene.vdb";
    auto ball = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(15.0f, openvdb::Vec3f(0.0f), 1.0f, 3.0f);
    ball->setName("ball");
    auto cd = openvdb::Vec3SGrid::create(openvdb::Vec3s(0));
    cd->setName("Cd");
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 8000; ++i) cd->tree().setValue(openvdb::Coord(i % 20, (i / 20) % 20, i / 400), openvdb::Vec3s(u(rng), u(rng), u(rng)));
    openvdb::io::File(p.string()).write({ball, cd});
    return p;
}

} // namespace

TEST(CliAttributes, ColourAndNormalReportsInEncodeAndInfo) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_cliattr_" + std::to_string(getpid()));
    fs::remove_all(dir);  // a finished process with the same PID may have left it
    fs::create_directories(dir);
    const fs::path in = inputFile(dir), out = dir / "scene.ssvdag";
    CliRun r = run("encode " + in.string() + " -o " + out.string() + " --color-bits 10 --normals 16 --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto enc = nlohmann::json::parse(r.out);
    ASSERT_EQ(enc["grids_colour"].size(), 1u);
    EXPECT_EQ(enc["grids_colour"][0]["name"], "Cd");
    EXPECT_EQ(enc["grids_colour"][0]["distinct_after"].get<uint64_t>(), 1024u);
    EXPECT_EQ(enc["grids_colour"][0]["entries"].get<uint64_t>(), 8000u);
    ASSERT_EQ(enc["grids_normals"].size(), 1u);
    EXPECT_EQ(enc["grids_normals"][0]["name"], "ball");
    EXPECT_LE(enc["grids_normals"][0]["max_angle_degrees"].get<double>(), 0.95);

    r = run("info " + out.string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto info = nlohmann::json::parse(r.out);
    bool sawColour = false, sawNormals = false;
    for (const auto& g : info["grids"]) {
        if (g.contains("colour")) {
            sawColour = true;
            EXPECT_EQ(g["colour"], enc["grids_colour"][0]) << "info reads back what encode measured";
        }
        if (g.contains("normals")) {
            sawNormals = true;
            EXPECT_EQ(g["normals"]["entries"], enc["grids_normals"][0]["entries"]);
            bool section = false;
            for (const auto& s : g["sections"]) section |= s["kind"] == "Normals";
            EXPECT_TRUE(section);
        }
    }
    EXPECT_TRUE(sawColour);
    EXPECT_TRUE(sawNormals);
    r = run("info " + out.string());
    EXPECT_NE(r.out.find("ΔE94 mean"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("16-bit ONV from the gradient"), std::string::npos) << r.out;

    // Bad values: one line, non-zero exit, no output file.
    const fs::path bad = dir / "bad.ssvdag";
    for (const std::string& args : {std::string("--normals 11"), std::string("--colour-bits 17"), std::string("--colour-bits 10 --colour-grid ball"),
                                    std::string("--colour-bits 10 --colour-grid nope"), std::string("--normals 16 --normal-grid ball")}) {
        r = run("encode " + in.string() + " -o " + bad.string() + " " + args);
        EXPECT_NE(r.exitCode, 0) << args;
        EXPECT_FALSE(fs::exists(bad)) << args;
        EXPECT_FALSE(r.err.empty()) << args;
    }
    r = run("encode " + in.string() + " -o " + bad.string() + " --colour-bits 10 --colour-grid ball");
    EXPECT_NE(r.err.find("not vec3 colours"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    // A colour grid holding NaN is refused, naming the file and the grid.
    {
        auto cd = openvdb::Vec3SGrid::create(openvdb::Vec3s(0));
        cd->setName("Cd");
        cd->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(0.5f, std::nanf(""), 0.5f));
        const fs::path nanFile = dir / "nan_colour.vdb";
        openvdb::io::File(nanFile.string()).write({cd});
        r = run("encode " + nanFile.string() + " -o " + bad.string() + " --colour-bits 10");
        EXPECT_NE(r.exitCode, 0);
        EXPECT_FALSE(fs::exists(bad));
        EXPECT_NE(r.err.find(nanFile.string() + ": grid 'Cd'"), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    }
    fs::remove_all(dir);
}
