// `vdbdag bench` pieces against closed forms (Pareto front, PSNR, SSIM) and
// the command end to end on a small level set: every file written, every
// lossy vdbdag point within its bound, and at every matched error vdbdag's
// point is no larger in error than the peer's measured one (its bound).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "tests/unit/BuildPaths.h"
#include "src/bench/BenchPoint.h"
#include "src/bench/ImageMetrics.h"

namespace fs = std::filesystem;
using namespace vdbdag;

TEST(Bench, ParetoFrontKeepsOnlyUndominatedPoints) {
    // (size, error): (1,5) (2,3) (3,4) (4,1) (5,1) (0.5,9) (2,3)dup
    const std::vector<double> x{1, 2, 3, 4, 5, 0.5, 2};
    const std::vector<double> y{5, 3, 4, 1, 1, 9, 3};
    EXPECT_EQ(bench::paretoFront(x, y), (std::vector<size_t>{0, 1, 3, 5}));
    EXPECT_TRUE(bench::paretoFront({}, {}).empty());
}

TEST(Bench, PsnrAndSsimOfKnownImages) {
    trace::Image a, b;
    a.resize(32, 32);
    b.resize(32, 32);
    for (size_t i = 0; i < a.rgb.size(); ++i) a.rgb[i] = b.rgb[i] = float((i * 37) % 100) / 100.f;
    EXPECT_TRUE(std::isinf(bench::psnr(a, b)));
    EXPECT_DOUBLE_EQ(bench::ssim(a, b), 1.0);
    // Black against white: display MSE 1, PSNR 0 dB.
    std::fill(a.rgb.begin(), a.rgb.end(), 0.f);
    std::fill(b.rgb.begin(), b.rgb.end(), 1.f);
    EXPECT_NEAR(bench::psnr(a, b), 0.0, 1e-12);
    EXPECT_LT(bench::ssim(a, b), 0.01);
    // A display-space offset of 0.1 everywhere: MSE 0.01, PSNR 20 dB (white 1.0 -> display 1.0, so use linear values whose display differ by 0.1).
    auto toLinear = [](double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); };
    std::fill(a.rgb.begin(), a.rgb.end(), float(toLinear(0.5)));
    std::fill(b.rgb.begin(), b.rgb.end(), float(toLinear(0.6)));
    EXPECT_NEAR(bench::psnr(a, b), 20.0, 1e-3);
}

TEST(Bench, CommandWritesTheReportAndHoldsItsBounds) {
    openvdb::initialize();
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_bench_test_" + std::to_string(::getpid()));
    fs::remove_all(dir);  // a finished process with the same PID may have left it
    fs::create_directories(dir);
    const fs::path input = dir / "sphere.vdb";
    {
        auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.0f), 1.0f / 24.0f, 3.0f);
        grid->setName("sphere");
        openvdb::io::File file(input.string());
        file.write({grid});
    }
    const fs::path report = dir / "report";
    const std::string command = std::string(VDBDAG_BINARY) + " bench " + input.string() + " -o " + report.string() +
                                " --sweep quick --width 64 --height 48 --json > " + (dir / "out.json").string();
    ASSERT_EQ(std::system(command.c_str()), 0);
    for (const char* name : {"report.md", "report.csv", "report.json", "error_vs_size_sphere.png", "error_vs_time_sphere.png"})
        EXPECT_TRUE(fs::exists(report / name)) << name;
    std::ifstream in(report / "report.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    int lossless = 0, fpn = 0, matched = 0, normalRows = 0;
    uint64_t losslessBytes = 0;
    std::map<std::string, double> peerError;
    for (const auto& p : j["points"]) {
        const std::string tool = p["tool"], setting = p["setting"], family = p["family"];
        EXPECT_GT(p["bytes"].get<uint64_t>(), 0u) << tool << " " << setting;
        if (tool == "vdbdag" && setting == "lossless") {
            ++lossless;
            losslessBytes = p["bytes"].get<uint64_t>();
            EXPECT_TRUE(p["exact"].get<bool>());
            EXPECT_EQ(p["metric"], "value");
        }
        if (family == "vdbdag normals") {  // quick sweep: 16-bit ONVs, within the octahedral bound 0.95 * 2^((16-k)/2) degrees
            ++normalRows;
            EXPECT_EQ(setting, "normals ONV 16 bits");
            EXPECT_EQ(p["metric"], "normal angle deg");
            EXPECT_GT(p["max_error"].get<double>(), 0.0);
            EXPECT_LE(p["max_error"].get<double>(), 0.95);
            EXPECT_LE(p["mean_error"].get<double>(), p["max_error"].get<double>());
        }
        if (family == "vdbdag abs") {  // "abs E": every value within E
            const double bound = std::stod(setting.substr(4));
            EXPECT_LE(p["max_error"].get<double>(), bound * (1 + 1e-12));
        }
        if (family == "NanoVDB FpN") { ++fpn; peerError["matched to NanoVDB " + setting] = p["max_error"]; }
        if (family == "ZFP") peerError["matched to ZFP " + setting] = p["max_error"];
    }
    for (const auto& p : j["points"])
        if (p["family"] == "vdbdag matched") {
            ++matched;
            ASSERT_TRUE(peerError.count(p["note"].get<std::string>())) << p["note"];
            EXPECT_LE(p["max_error"].get<double>(), peerError[p["note"].get<std::string>()]);
        }
    EXPECT_EQ(lossless, 1);
    EXPECT_EQ(normalRows, 1);
    for (const auto& p : j["points"])  // the normals cost bytes on top of the exact values
        if (p["family"] == "vdbdag normals") { EXPECT_GT(p["bytes"].get<uint64_t>(), losslessBytes); }
    EXPECT_TRUE(fs::exists(report / "error_vs_size_sphere_normal_angle_deg.png"));
    EXPECT_GE(fpn, 2);
    EXPECT_GE(matched, fpn);
    fs::remove_all(dir);
}

TEST(Bench, ColourGridGetsColourRowsWithinTheirPaletteSize) {
    // A smooth RGB gradient of 32^3 distinct colours: the quick sweep's
    // 12-bit row keeps at most 4096 colours, with a positive ΔE94.
    openvdb::initialize();
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_bench_colour_" + std::to_string(::getpid()));
    fs::remove_all(dir);  // a finished process with the same PID may have left it
    fs::create_directories(dir);
    const fs::path input = dir / "cd.vdb";
    {
        auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3f(0.f));
        grid->setName("Cd");
        auto acc = grid->getAccessor();
        for (int x = 0; x < 32; ++x)
            for (int y = 0; y < 32; ++y)
                for (int z = 0; z < 32; ++z) acc.setValue({x, y, z}, openvdb::Vec3f(x / 31.f, y / 31.f, z / 31.f));
        openvdb::io::File file(input.string());
        file.write({grid});
    }
    const fs::path report = dir / "report";
    const std::string command = std::string(VDBDAG_BINARY) + " bench " + input.string() + " -o " + report.string() +
                                " --sweep quick --width 48 --height 32 > /dev/null";
    ASSERT_EQ(std::system(command.c_str()), 0);
    std::ifstream in(report / "report.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    int colourRows = 0;
    for (const auto& p : j["points"])
        if (p["family"] == "vdbdag colour") {
            ++colourRows;
            EXPECT_EQ(p["setting"], "colour 12 bits");
            EXPECT_EQ(p["metric"], "colour dE94");
            EXPECT_FALSE(p["exact"].get<bool>());
            EXPECT_GT(p["max_error"].get<double>(), 0.0);
            EXPECT_LE(p["mean_error"].get<double>(), p["max_error"].get<double>());
            const std::string note = p["note"];
            EXPECT_NE(note.find("32768 -> "), std::string::npos) << note;
            const uint64_t after = std::stoull(note.substr(note.find("-> ") + 3));
            EXPECT_LE(after, 4096u) << note;
            EXPECT_GT(p["render_psnr_db"].get<double>(), 20.0);
        }
    EXPECT_EQ(colourRows, 1);
    EXPECT_TRUE(fs::exists(report / "error_vs_size_Cd_colour_dE94.png"));
    fs::remove_all(dir);
}

TEST(Bench, MissingInputFailsWithOneLineAndNoReport) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_bench_missing_" + std::to_string(::getpid()));
    const std::string command = std::string(VDBDAG_BINARY) + " bench /nonexistent/file.vdb -o " + dir.string() + " 2> " + dir.string() + ".err";
    EXPECT_NE(std::system(command.c_str()), 0);
    EXPECT_FALSE(fs::exists(dir / "report.md"));
    std::ifstream err(dir.string() + ".err");
    std::string line, extra;
    std::getline(err, line);
    EXPECT_NE(line.find("vdbdag:"), std::string::npos);
    EXPECT_FALSE(std::getline(err, extra)) << "more than one line: " << extra;
    fs::remove(dir.string() + ".err");
}
