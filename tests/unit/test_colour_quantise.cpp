// Lossy colours (--colour-bits): encoded through the whole pipeline and the
// file, decoded to a .vdb and checked there with OpenVDB's accessors against
// the original grid: at most 2^k distinct colours, every voxel within the
// reported max ΔE94, the reported means/maxima recomputed independently,
// extremes (black, white, primaries) kept, vec3i handled, bad input refused,
// non-colour vec3 grids untouched.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <set>

#include <openvdb/openvdb.h>
#include <tbb/global_control.h>

#include "src/attributes/CieLab.h"
#include "src/attributes/ColourQuantizer.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "vdb_bridge/VdbExport.h"
#include "vdb_bridge/VdbImport.h"

using namespace vdbdag;
namespace fs = std::filesystem;

namespace {

fs::path tempDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_colour_" + std::to_string(getpid()));
        fs::remove_all(d);  // a finished process with the same PID may have left it
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

// A 40^3 block of random colours (64,000 voxels, all distinct) plus the
// eight corners of the RGB cube at known voxels.
template <typename GridT>
typename GridT::Ptr randomColourGrid(const std::string& name, uint32_t seed, bool withExtremes) {
    using V = typename GridT::ValueType;
    auto grid = GridT::create(V(0));
    grid->setName(name);
    std::mt19937 rng(seed);
    auto acc = grid->getAccessor();
    for (int x = 0; x < 40; ++x)
        for (int y = 0; y < 40; ++y)
            for (int z = 0; z < 40; ++z) {
                V v;
                if constexpr (std::is_same_v<V, openvdb::Vec3i>) {
                    std::uniform_int_distribution<int> u(0, 255);
                    v = V(u(rng), u(rng), u(rng));
                } else {
                    std::uniform_real_distribution<double> u(0.0, 1.0);
                    v = V(u(rng), u(rng), u(rng));
                }
                acc.setValue(openvdb::Coord(x, y, z), v);
            }
    if (withExtremes)
        for (int c = 0; c < 8; ++c) {
            const int top = std::is_same_v<V, openvdb::Vec3i> ? 255 : 1;
            acc.setValue(openvdb::Coord(100 + c, 0, 0), V((c & 1) * top, ((c >> 1) & 1) * top, ((c >> 2) & 1) * top));
        }
    return grid;
}

template <typename V>
attributes::Rgb rgbOf(const V& v) {
    const double s = std::is_same_v<V, openvdb::Vec3i> ? 255.0 : 1.0;
    return {double(v[0]) / s, double(v[1]) / s, double(v[2]) / s};
}

// Encode `path` with `options`, write and read the .ssvdag, decode to .vdb.
format::SsvdagScene roundTrip(const fs::path& in, const fs::path& out, const pipeline::EncodeOptions& options) {
    const auto bytes = format::writeScene(pipeline::encodeVolume(bridge::importVdb(in.string()).volume, options));
    format::SsvdagScene scene = format::readScene(bytes, "colour test");
    bridge::exportVdb(pipeline::decodeScene(scene), out.string());
    return scene;
}

template <typename GridT>
typename GridT::Ptr readGrid(const fs::path& path, const std::string& name) {
    openvdb::io::File f(path.string());
    f.open();
    auto g = openvdb::gridPtrCast<GridT>(f.readGrid(name));
    f.close();
    return g;
}

// Independent check of a decoded colour grid against its original.
template <typename GridT>
void checkQuantised(const GridT& original, const GridT& decoded, const attributes::ColourReport& report, unsigned bits) {
    using V = typename GridT::ValueType;
    ASSERT_EQ(decoded.activeVoxelCount(), original.activeVoxelCount());
    auto acc = decoded.getConstAccessor();
    std::set<std::array<double, 3>> distinct;
    std::array<double, 3> sumAbs{}, maxAbs{};
    double sumDe = 0, maxDe = 0;
    uint64_t n = 0;
    const double scale = std::is_same_v<V, openvdb::Vec3i> ? 1.0 : 255.0;
    for (auto it = original.cbeginValueOn(); it; ++it, ++n) {
        V q;
        ASSERT_TRUE(acc.probeValue(it.getCoord(), q)) << "voxel stays active";
        distinct.insert({double(q[0]), double(q[1]), double(q[2])});
        const V o = *it;
        if constexpr (std::is_same_v<V, openvdb::Vec3i>) {
            for (int k = 0; k < 3; ++k) ASSERT_TRUE(q[k] >= 0 && q[k] <= 255);
        }
        for (int k = 0; k < 3; ++k) {
            const double e = std::fabs(double(q[k]) - double(o[k])) * scale;
            sumAbs[k] += e;
            maxAbs[k] = std::max(maxAbs[k], e);
        }
        const double de = attributes::deltaE94(attributes::srgbToLab(rgbOf(o)), attributes::srgbToLab(rgbOf(q)));
        ASSERT_LE(de, report.maxDeltaE94 + 1e-9) << "every voxel within the reported max";
        sumDe += de;
        maxDe = std::max(maxDe, de);
    }
    EXPECT_LE(distinct.size(), size_t(1) << bits);
    EXPECT_EQ(report.distinctAfter, distinct.size());
    EXPECT_EQ(report.entries, n);
    EXPECT_NEAR(report.maxDeltaE94, maxDe, 1e-9);
    EXPECT_NEAR(report.meanDeltaE94, sumDe / double(n), 1e-9);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(report.maxAbsError[k], maxAbs[k], 1e-6);
        EXPECT_NEAR(report.meanAbsError[k], sumAbs[k] / double(n), 1e-6);
    }
}

} // namespace

TEST(ColourQuantise, Vec3sGridKeepsAtMost2PowKColoursWithTheReportedErrors) {
    openvdb::initialize();
    auto grid = randomColourGrid<openvdb::Vec3SGrid>("Cd", 1, true);
    const fs::path in = tempDir() / "cd.vdb", out = tempDir() / "cd_q.vdb";
    openvdb::io::File(in.string()).write({grid});
    for (unsigned bits : {10u, 12u}) {
        pipeline::EncodeOptions options;
        options.colourBits = bits;
        const auto scene = roundTrip(in, out, options);
        ASSERT_TRUE(scene.grids[0].colour.has_value());
        const auto& report = *scene.grids[0].colour;
        EXPECT_EQ(report.distinctBefore, 64008u);
        EXPECT_EQ(report.distinctAfter, uint64_t(1) << bits) << "random colours use every representative";
        EXPECT_GT(report.maxDeltaE94, 0.0);
        EXPECT_LT(report.meanDeltaE94, bits == 10 ? 4.0 : 2.0);  // Dado et al. Table 2 reports ΔE of a few units at 10-12 bits
        const auto decoded = readGrid<openvdb::Vec3SGrid>(out, "Cd");
        ASSERT_TRUE(decoded);
        checkQuantised(*grid, *decoded, report, bits);
        // The corners of the RGB cube (black, white, primaries) seed the
        // clustering: they survive exactly.
        auto acc = decoded->getConstAccessor();
        for (int c = 0; c < 8; ++c) {
            const openvdb::Coord at(100 + c, 0, 0);
            const double de = attributes::deltaE94(attributes::srgbToLab(rgbOf(grid->tree().getValue(at))), attributes::srgbToLab(rgbOf(acc.getValue(at))));
            EXPECT_LT(de, 1e-9) << "corner " << c;
        }
    }
}

TEST(ColourQuantise, Vec3iColoursStayIntegersIn0To255) {
    openvdb::initialize();
    auto grid = randomColourGrid<openvdb::Vec3IGrid>("color", 2, true);
    const fs::path in = tempDir() / "ci.vdb", out = tempDir() / "ci_q.vdb";
    openvdb::io::File(in.string()).write({grid});
    pipeline::EncodeOptions options;
    options.colourBits = 10;
    const auto scene = roundTrip(in, out, options);
    ASSERT_TRUE(scene.grids[0].colour.has_value());
    const auto decoded = readGrid<openvdb::Vec3IGrid>(out, "color");
    ASSERT_TRUE(decoded);
    checkQuantised(*grid, *decoded, *scene.grids[0].colour, 10);
}

TEST(ColourQuantise, IdenticalColoursAndFewColoursStayExact) {
    openvdb::initialize();
    auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0));
    grid->setName("rgb");
    grid->fill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(20)), openvdb::Vec3s(0.2f, 0.4f, 0.6f), true);
    grid->tree().setValue(openvdb::Coord(30, 0, 0), openvdb::Vec3s(1.0f, 0.0f, 0.0f));
    const fs::path in = tempDir() / "same.vdb", out = tempDir() / "same_q.vdb";
    openvdb::io::File(in.string()).write({grid});
    pipeline::EncodeOptions options;
    options.colourBits = 1;  // 2 colours: exactly what the grid holds
    const auto scene = roundTrip(in, out, options);
    ASSERT_TRUE(scene.grids[0].colour.has_value());
    EXPECT_EQ(scene.grids[0].colour->changed, 0u);
    EXPECT_EQ(scene.grids[0].colour->maxDeltaE94, 0.0);
    const auto decoded = readGrid<openvdb::Vec3SGrid>(out, "rgb");
    auto acc = decoded->getConstAccessor();
    for (auto it = grid->cbeginValueOn(); it; ++it) ASSERT_EQ(acc.getValue(it.getCoord()), *it);
}

TEST(ColourQuantise, NonColourVec3GridsAreUntouchedAndNamedGridsAreChosen) {
    openvdb::initialize();
    auto vel = randomColourGrid<openvdb::Vec3SGrid>("vel", 3, false);
    auto tint = randomColourGrid<openvdb::Vec3SGrid>("tint", 4, false);
    const fs::path in = tempDir() / "vel.vdb", out = tempDir() / "vel_q.vdb";
    openvdb::io::File(in.string()).write({vel, tint});
    pipeline::EncodeOptions options;
    options.colourBits = 10;
    auto scene = roundTrip(in, out, options);
    // OpenVDB may reorder grids in the file: find them by name.
    auto byName = [&](const std::string& name) -> const format::EncodedGrid& {
        for (const auto& g : scene.grids)
            if (g.record.name == name) return g;
        throw std::runtime_error("no grid " + name);
    };
    EXPECT_FALSE(byName("vel").colour.has_value());
    EXPECT_FALSE(byName("tint").colour.has_value()) << "'tint' is not a default colour name";
    auto decoded = readGrid<openvdb::Vec3SGrid>(out, "vel");
    auto acc = decoded->getConstAccessor();
    for (auto it = vel->cbeginValueOn(); it; ++it) ASSERT_EQ(acc.getValue(it.getCoord()), *it) << "bit-exact";
    options.colourGrids = {"tint"};
    scene = roundTrip(in, out, options);
    EXPECT_FALSE(byName("vel").colour.has_value());
    ASSERT_TRUE(byName("tint").colour.has_value());
    checkQuantised(*tint, *readGrid<openvdb::Vec3SGrid>(out, "tint"), *byName("tint").colour, 10);
}

TEST(ColourQuantise, NanAndOutOfRangeColoursAreRefusedWithOneLine) {
    openvdb::initialize();
    for (const openvdb::Vec3s bad : {openvdb::Vec3s(std::nanf(""), 0.5f, 0.5f), openvdb::Vec3s(0.5f, INFINITY, 0.5f), openvdb::Vec3s(1.5f, 0.f, 0.f)}) {
        auto grid = randomColourGrid<openvdb::Vec3SGrid>("Cd", 5, false);
        grid->tree().setValue(openvdb::Coord(7, 7, 7), bad);
        const fs::path in = tempDir() / "bad.vdb";
        openvdb::io::File(in.string()).write({grid});
        pipeline::EncodeOptions options;
        options.colourBits = 10;
        try {
            pipeline::encodeVolume(bridge::importVdb(in.string()).volume, options);
            FAIL() << "accepted " << bad;
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find("'Cd'"), std::string::npos) << m;
            EXPECT_NE(m.find("not an sRGB colour"), std::string::npos) << m;
            EXPECT_EQ(m.find('\n'), std::string::npos);
        }
    }
}

TEST(ColourQuantise, ColourSectionIsStoredOnlyWhenAskedAndCorruptionIsRefused) {
    openvdb::initialize();
    auto grid = randomColourGrid<openvdb::Vec3SGrid>("Cd", 6, false);
    const fs::path in = tempDir() / "sec.vdb";
    openvdb::io::File(in.string()).write({grid});
    const auto volume = bridge::importVdb(in.string()).volume;
    auto kinds = [](const std::vector<uint8_t>& bytes) {
        std::set<format::SectionKind> k;
        for (const auto& s : format::summarizeContainer(bytes, "t")) k.insert(s.kind);
        return k;
    };
    EXPECT_FALSE(kinds(format::writeScene(pipeline::encodeVolume(volume))).count(format::SectionKind::ColourErrors));
    pipeline::EncodeOptions options;
    options.colourBits = 10;
    auto sections = format::sceneToSections(pipeline::encodeVolume(volume, options));
    bool found = false;
    for (auto& s : sections)
        if (s.kind == format::SectionKind::ColourErrors) {
            found = true;
            s.data[0] = 40;  // 40 colour bits
        }
    ASSERT_TRUE(found);
    try {
        format::readScene(format::writeContainer(sections), "bad.ssvdag");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("ColourErrors"), std::string::npos) << e.what();
    }
}

TEST(ColourQuantise, KMeansPassesLowerTheMeanAndKeepTheFarthestPointMaximum) {
    // 200,000 random colours, quantised to 2^10 with and without refinement.
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> v(200000 * 3);
    for (float& x : v) x = u(rng);
    std::vector<uint8_t> input(v.size() * 4);
    std::memcpy(input.data(), v.data(), input.size());
    auto maxDeltaE76 = [&](const std::vector<uint8_t>& q) {
        double m = 0;
        for (size_t i = 0; i < v.size() / 3; ++i) {
            const auto a = attributes::srgbToLab(attributes::colourOf(&input[i * 12], ValueType::Vec3S));
            const auto b = attributes::srgbToLab(attributes::colourOf(&q[i * 12], ValueType::Vec3S));
            m = std::max(m, std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2])));
        }
        return m;
    };
    auto plain = input, refined = input, refinedOneThread = input;
    const auto plainReport = attributes::quantiseColours(plain, ValueType::Vec3S, 10, "plain", 0);
    const auto refinedReport = attributes::quantiseColours(refined, ValueType::Vec3S, 10, "refined");
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        attributes::quantiseColours(refinedOneThread, ValueType::Vec3S, 10, "refined");
    }
    EXPECT_EQ(refined, refinedOneThread) << "deterministic for any thread count";
    EXPECT_LT(refinedReport.meanDeltaE94, plainReport.meanDeltaE94 * 0.95);
    EXPECT_LE(maxDeltaE76(refined), maxDeltaE76(plain) + 1e-9) << "the farthest-point radius still bounds every error";
    EXPECT_LE(refinedReport.distinctAfter, 1024u);
}
