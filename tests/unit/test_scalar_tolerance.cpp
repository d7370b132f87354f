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

// Integers (issue 37's near-lossless): --abs-error N on an int32 or int64
// channel moves each value to the nearest multiple of 2 floor(N) + 1, so
// every value is within floor(N) (brute force), a value whose multiple
// leaves the type stays exact, the report's figures are the brute-force
// ones, and --rel-error leaves integers exact.
TEST(ScalarTolerance, IntegersAreNearLosslessWithinTheIntegerBound) {
    std::mt19937 rng(37);
    std::vector<int32_t> v(20000);
    for (auto& x : v) x = int32_t(rng() % 4096) - 1024;
    v[0] = INT32_MIN, v[1] = INT32_MAX, v[2] = 0;
    std::vector<uint8_t> bytes(v.size() * 4);
    std::memcpy(bytes.data(), v.data(), bytes.size());
    const attributes::ToleranceReport r = attributes::applyScalarTolerance(bytes, ValueType::Int32, {attributes::ScalarTolerance::Mode::Absolute, 2.7});
    std::vector<int32_t> q(v.size());
    std::memcpy(q.data(), bytes.data(), bytes.size());
    double maxErr = 0, sum = 0;
    uint64_t changed = 0;
    for (size_t i = 0; i < v.size(); ++i) {
        const int64_t e = std::llabs(int64_t(q[i]) - v[i]);
        ASSERT_LE(e, 2) << i;
        if (i > 0) { EXPECT_EQ(((int64_t(q[i]) % 5) + 5) % 5, 0) << i; }  // multiples of 2*2+1
        maxErr = std::max(maxErr, double(e));
        sum += double(e);
        changed += e != 0;
    }
    EXPECT_EQ(q[0], INT32_MIN);  // its nearest multiple of 5 would leave int32
    EXPECT_EQ(q[1], INT32_MAX - 2);
    EXPECT_EQ(r.keptExact, 1u);
    EXPECT_EQ(r.changed, changed);
    EXPECT_EQ(r.maxAbsError, maxErr);
    EXPECT_NEAR(r.meanAbsError, sum / double(v.size()), 1e-12);
    // Relative: integers stay as they are; a bound under 1 changes nothing.
    std::vector<uint8_t> same(v.size() * 4);
    std::memcpy(same.data(), v.data(), same.size());
    EXPECT_EQ(attributes::applyScalarTolerance(same, ValueType::Int32, {attributes::ScalarTolerance::Mode::Relative, 0.1}).changed, 0u);
    EXPECT_EQ(attributes::applyScalarTolerance(same, ValueType::Int32, {attributes::ScalarTolerance::Mode::Absolute, 0.9}).changed, 0u);
    EXPECT_EQ(std::memcmp(same.data(), v.data(), same.size()), 0);
    // int64 beyond double's 53 bits: exact integer arithmetic.
    std::vector<int64_t> w{(int64_t(1) << 60) + 3, -(int64_t(1) << 60) - 4, 7};
    std::vector<uint8_t> wb(w.size() * 8);
    std::memcpy(wb.data(), w.data(), wb.size());
    attributes::applyScalarTolerance(wb, ValueType::Int64, {attributes::ScalarTolerance::Mode::Absolute, 1});
    std::vector<int64_t> wq(w.size());
    std::memcpy(wq.data(), wb.data(), wb.size());
    for (size_t i = 0; i < w.size(); ++i) {
        EXPECT_LE(std::llabs(wq[i] - w[i]), 1);
        EXPECT_EQ(((wq[i] % 3) + 3) % 3, 0);
    }
}

// End to end: an int32 grid (a dense 48^3 block of CT-like samples) encoded
// with --abs-error 2 is smaller than lossless, and every voxel OpenVDB reads
// back from the decoded .vdb is within 2 of the original (brute force).
TEST(ScalarTolerance, EndToEndIntegersWithinTheBound) {
    openvdb::initialize();
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_tol_int_" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto g = openvdb::Int32Grid::create(-1024);
    g->setName("ct");
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, 8.0);
    auto acc0 = g->getAccessor();
    for (int z = 0; z < 48; ++z)
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 48; ++x)
                acc0.setValue({x, y, z}, int32_t(std::lround(40 + 300 * std::sin(x / 9.0) * std::cos(y / 7.0) + 2 * z + noise(rng))));
    const fs::path in = dir / "ct.vdb", out = dir / "ct_lossy.vdb";
    openvdb::io::File(in.string()).write({g});
    pipeline::EncodeOptions options;
    options.tolerance = {attributes::ScalarTolerance::Mode::Absolute, 2};
    const auto exact = format::writeScene(pipeline::encodeVolume(bridge::importVdb(in.string()).volume));
    const auto lossy = format::writeScene(pipeline::encodeVolume(bridge::importVdb(in.string()).volume, options));
    EXPECT_LT(double(lossy.size()), 0.8 * double(exact.size()));
    const auto scene = format::readScene(lossy, "lossy");
    EXPECT_EQ(scene.grids[0].lossy.maxAbsError, 2);
    bridge::exportVdb(pipeline::decodeScene(scene), out.string());
    openvdb::io::File f(out.string());
    f.open();
    const auto back = openvdb::gridPtrCast<openvdb::Int32Grid>(f.readGrid("ct"));
    ASSERT_TRUE(back);
    auto acc = back->getConstAccessor();
    uint64_t checked = 0;
    for (auto it = g->cbeginValueOn(); it; ++it, ++checked) {
        ASSERT_TRUE(acc.isValueOn(it.getCoord()));
        ASSERT_LE(std::llabs(int64_t(acc.getValue(it.getCoord())) - *it), 2);
    }
    EXPECT_EQ(checked, uint64_t(48 * 48 * 48));
    EXPECT_EQ(checked, back->activeVoxelCount());
    fs::remove_all(dir);
}
