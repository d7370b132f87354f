// Lossy scalar tolerances: every decoded value checked against the bound by
// brute force, specials kept exact, stiff ranges (1e-30..1e30) and outliers
// handled; and end to end through the file and OpenVDB.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <set>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "src/attributes/ScalarTolerance.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "vdb_bridge/VdbExport.h"
#include "vdb_bridge/VdbImport.h"

using namespace vdbdag;
namespace fs = std::filesystem;

namespace {

std::vector<uint8_t> bytesOf(const std::vector<float>& v) {
    std::vector<uint8_t> b(v.size() * 4);
    std::memcpy(b.data(), v.data(), b.size());
    return b;
}
std::vector<float> floatsOf(const std::vector<uint8_t>& b) {
    std::vector<float> v(b.size() / 4);
    std::memcpy(v.data(), b.data(), b.size());
    return v;
}
float fromBits(uint32_t bits) { float f; std::memcpy(&f, &bits, 4); return f; }

} // namespace

TEST(ScalarTolerance, AbsoluteBoundHoldsAndSpecialsStayExact) {
    std::mt19937 rng(8);
    std::uniform_real_distribution<float> u(-3.0f, 3.0f);
    std::vector<float> v(100000);
    for (auto& x : v) x = u(rng);
    v[0] = fromBits(0x7FC00123u); v[1] = -0.0f; v[2] = 0.0f; v[3] = std::numeric_limits<float>::infinity();
    v[4] = 1e30f;                         // an outlier in a field of -3..3: float spacing there exceeds E, so it stays exact
    v[5] = std::numeric_limits<float>::denorm_min();
    auto bytes = bytesOf(v);
    const double E = 0.0005;
    const auto report = attributes::applyScalarTolerance(bytes, ValueType::Float, {attributes::ScalarTolerance::Mode::Absolute, E});
    const auto q = floatsOf(bytes);
    double maxErr = 0;
    for (size_t i = 0; i < v.size(); ++i) {
        if (!std::isfinite(v[i])) { EXPECT_EQ(std::memcmp(&q[i], &v[i], 4), 0); continue; }
        const double err = std::fabs(double(q[i]) - double(v[i]));
        EXPECT_LE(err, E) << i;
        EXPECT_EQ(std::signbit(q[i]), std::signbit(v[i])) << "the sign (level-set side) survives";
        maxErr = std::max(maxErr, err);
    }
    EXPECT_EQ(std::memcmp(&q[1], &v[1], 4), 0) << "-0.0 keeps its sign";
    EXPECT_EQ(q[4], 1e30f);
    EXPECT_DOUBLE_EQ(report.maxAbsError, maxErr);
    EXPECT_GT(report.changed, 90000u);
    std::set<float> distinct(q.begin() + 6, q.end());
    EXPECT_LE(distinct.size(), size_t(6.0 / (2 * E)) + 2 + report.keptExact);  // values exactly between two levels may stay exact
    EXPECT_LT(report.keptExact, 100u);
}

TEST(ScalarTolerance, RelativeBoundHoldsFrom1e30Down) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> exponent(-30.0, 30.0);
    std::vector<float> v(100000);
    for (auto& x : v) x = float((rng() & 1 ? 1 : -1) * std::pow(10.0, exponent(rng)));
    v[0] = 0.0f; v[1] = -std::numeric_limits<float>::infinity();
    auto bytes = bytesOf(v);
    const double R = 0.001;
    const auto report = attributes::applyScalarTolerance(bytes, ValueType::Float, {attributes::ScalarTolerance::Mode::Relative, R});
    const auto q = floatsOf(bytes);
    for (size_t i = 0; i < v.size(); ++i) {
        if (!std::isfinite(v[i]) || v[i] == 0.0f) { EXPECT_EQ(std::memcmp(&q[i], &v[i], 4), 0); continue; }
        EXPECT_LE(std::fabs(double(q[i]) - double(v[i])), R * std::fabs(double(v[i])) * (1 + 1e-12)) << v[i] << " -> " << q[i];
        EXPECT_EQ(std::signbit(q[i]), std::signbit(v[i]));
    }
    EXPECT_LE(report.maxRelError, R);
    EXPECT_GT(report.changed, 99000u);  // quantised, not silently kept exact
}

TEST(ScalarTolerance, EndToEndEveryDecodedValueWithinTheBound) {
    openvdb::initialize();
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_tol_" + std::to_string(getpid()));
    fs::remove_all(dir);  // a finished process with the same PID may have left it
    fs::create_directories(dir);
    auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(30.0f, openvdb::Vec3f(0.3f), 0.1f, 3.0f);
    g->setName("ls");
    const fs::path in = dir / "ls.vdb", out = dir / "ls_lossy.vdb";
    openvdb::io::File(in.string()).write({g});
    const double E = 0.01;
    pipeline::EncodeOptions options;
    options.tolerance = {attributes::ScalarTolerance::Mode::Absolute, E};
    const auto exact = format::writeScene(pipeline::encodeVolume(bridge::importVdb(in.string()).volume));
    const auto lossy = format::writeScene(pipeline::encodeVolume(bridge::importVdb(in.string()).volume, options));
    EXPECT_LT(lossy.size(), exact.size());
    const auto scene = format::readScene(lossy, "lossy");
    EXPECT_LE(scene.grids[0].lossy.maxAbsError, E);
    bridge::exportVdb(pipeline::decodeScene(scene), out.string());
    openvdb::io::File f(out.string());
    f.open();
    const auto back = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid("ls"));
    ASSERT_TRUE(back);
    auto acc = back->getConstAccessor();
    uint64_t checked = 0;
    for (auto it = g->cbeginValueOn(); it; ++it, ++checked) {
        ASSERT_TRUE(acc.isValueOn(it.getCoord()));
        ASSERT_LE(std::fabs(double(acc.getValue(it.getCoord())) - double(*it)), E);
    }
    EXPECT_EQ(checked, back->activeVoxelCount());
    // Inactive values (the inside/outside signs) stay exact.
    for (auto it = g->cbeginValueOff(); it; ++it) ASSERT_EQ(acc.getValue(it.getCoord()), *it);
    fs::remove_all(dir);
}
