// Dense scans in (raw, NRRD, MetaImage): every shared scan imports and comes
// back sample for sample through `import` and through `encode` + `decode`,
// checked against the data file read here with plain fread + byte swapping
// (gzip NRRD: inflated here with zlib), never with the project's reader;
// synthetic headers with odd spacings, oblique directions, big-endian and
// gzip data give the closed-form index-to-world map; malformed inputs give a
// one-line error and no output; thresholds report what they change.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <zlib.h>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"
#include "src/attributes/PredictedChannel.h"
#include "src/attributes/PredictedWindows.h"
#include "src/encoding/AttributeLayout.h"
#include "src/format/SsvdagFile.h"
#include "src/format/TraceableValues.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "vdb_bridge/DenseImport.h"

namespace fs = std::filesystem;

namespace {

using vdbdag::testing::CommandResult;
using vdbdag::testing::runCli;

fs::path workDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_dense_" + std::to_string(getpid()));
        fs::remove_all(d);  // a finished process with the same PID may have left it
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

fs::path denseDir() { return fs::path(VDBDAG_SHARED_DATA) / "dense"; }

void writeBytes(const fs::path& p, const void* data, size_t n, const std::string& prefix = "") {
    std::ofstream out(p, std::ios::binary);
    out.write(prefix.data(), std::streamsize(prefix.size()));
    out.write(static_cast<const char*>(data), std::streamsize(n));
}

std::vector<uint8_t> readAll(const fs::path& p) {
    std::vector<uint8_t> bytes(fs::file_size(p));
    FILE* f = std::fopen(p.c_str(), "rb");
    EXPECT_EQ(std::fread(bytes.data(), 1, bytes.size(), f), bytes.size());
    std::fclose(f);
    return bytes;
}

std::vector<uint8_t> gunzip(const uint8_t* data, size_t n, size_t expected) {
    std::vector<uint8_t> out(expected);
    z_stream z{};
    inflateInit2(&z, 15 + 32);
    z.next_in = const_cast<uint8_t*>(data);
    z.avail_in = unsigned(n);
    z.next_out = out.data();
    z.avail_out = unsigned(out.size());
    const int rc = inflate(&z, Z_FINISH);
    inflateEnd(&z);
    EXPECT_EQ(rc, Z_STREAM_END);
    return out;
}

std::vector<uint8_t> gzipBytes(const std::vector<uint8_t>& in) {
    std::vector<uint8_t> out(compressBound(uLong(in.size())) + 64);
    z_stream z{};
    deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);  // gzip wrapper
    z.next_in = const_cast<uint8_t*>(in.data());
    z.avail_in = unsigned(in.size());
    z.next_out = out.data();
    z.avail_out = unsigned(out.size());
    EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
}

// Samples as doubles (exact for every type up to 32 bits) plus raw bits for floats.
struct Expected {
    std::array<int, 3> dims;
    std::string type;  // u8 i8 u16 i16 u32 i32 f32 f64
    std::vector<uint8_t> bytes;  // host order
    size_t size() const { return size_t(dims[0]) * dims[1] * dims[2]; }
    unsigned width() const { return type == "f64" ? 8 : (type == "u8" || type == "i8") ? 1 : (type == "u16" || type == "i16") ? 2 : 4; }
    double value(size_t i) const {
        const uint8_t* p = bytes.data() + i * width();
        if (type == "u8") return *p;
        if (type == "i8") return int8_t(*p);
        if (type == "u16") { uint16_t v; std::memcpy(&v, p, 2); return v; }
        if (type == "i16") { int16_t v; std::memcpy(&v, p, 2); return v; }
        if (type == "u32") { uint32_t v; std::memcpy(&v, p, 4); return v; }
        if (type == "i32") { int32_t v; std::memcpy(&v, p, 4); return v; }
        if (type == "f32") { float v; std::memcpy(&v, p, 4); return v; }
        double v; std::memcpy(&v, p, 8); return v;
    }
};

Expected fromFile(const fs::path& data, size_t offset, std::array<int, 3> dims, const std::string& type, bool bigEndian, bool gzip = false) {
    Expected e{dims, type, {}};
    const std::vector<uint8_t> all = readAll(data);
    const size_t n = e.size() * e.width();
    if (gzip) e.bytes = gunzip(all.data() + offset, all.size() - offset, n);
    else e.bytes.assign(all.begin() + long(offset), all.begin() + long(offset + n));
    EXPECT_EQ(e.bytes.size(), n);
    if (bigEndian)
        for (size_t i = 0; i < n; i += e.width()) std::reverse(e.bytes.begin() + long(i), e.bytes.begin() + long(i + e.width()));
    return e;
}

openvdb::GridBase::Ptr readOnlyGrid(const fs::path& vdb) {
    openvdb::initialize();
    openvdb::io::File f(vdb.string());
    f.open();
    auto grids = f.getGrids();
    f.close();
    EXPECT_EQ(grids->size(), 1u);
    return grids->front();
}

// Every sample active with exactly the file's value (bit for bit for floats).
template <typename GridT>
void expectSamples(const GridT& grid, const Expected& e, const std::string& what) {
    using V = typename GridT::ValueType;
    EXPECT_EQ(grid.activeVoxelCount(), e.size()) << what;
    auto acc = grid.getConstAccessor();
    size_t bad = 0;
    for (int z = 0; z < e.dims[2]; ++z)
        for (int y = 0; y < e.dims[1]; ++y)
            for (int x = 0; x < e.dims[0]; ++x) {
                const size_t i = (size_t(z) * e.dims[1] + y) * e.dims[0] + x;
                const openvdb::Coord c(x, y, z);
                const V got = acc.getValue(c);
                bool same;
                if constexpr (std::is_floating_point_v<V>) {
                    same = std::memcmp(&got, e.bytes.data() + i * sizeof(V), sizeof(V)) == 0;
                } else {
                    same = double(got) == e.value(i);
                }
                if (!same || !acc.isValueOn(c)) ++bad;
            }
    EXPECT_EQ(bad, 0u) << what << ": samples that differ";
}

void expectGridMatches(const openvdb::GridBase::Ptr& g, const Expected& e, const std::string& what) {
    if (e.type == "f32") {
        ASSERT_TRUE(g->isType<openvdb::FloatGrid>()) << what;
        expectSamples(*openvdb::gridPtrCast<openvdb::FloatGrid>(g), e, what);
    } else if (e.type == "f64") {
        ASSERT_TRUE(g->isType<openvdb::DoubleGrid>()) << what;
        expectSamples(*openvdb::gridPtrCast<openvdb::DoubleGrid>(g), e, what);
    } else if (e.type == "u32") {
        ASSERT_TRUE(g->isType<openvdb::Int64Grid>()) << what;
        expectSamples(*openvdb::gridPtrCast<openvdb::Int64Grid>(g), e, what);
    } else {
        ASSERT_TRUE(g->isType<openvdb::Int32Grid>()) << what << " is " << g->type();
        expectSamples(*openvdb::gridPtrCast<openvdb::Int32Grid>(g), e, what);
    }
}

// world = origin + i*a0 + j*a1 + k*a2, checked at the corners and a middle point.
void expectTransform(const openvdb::GridBase& g, const std::array<double, 3>& origin, const std::array<std::array<double, 3>, 3>& axes,
                     const std::array<int, 3>& dims, const std::string& what) {
    for (const auto& ijk : {std::array<double, 3>{0, 0, 0}, {double(dims[0] - 1), 0, 0}, {0, double(dims[1] - 1), 0},
                            {0, 0, double(dims[2] - 1)}, {1.5, 2.25, 3.0}, {double(dims[0] - 1), double(dims[1] - 1), double(dims[2] - 1)}}) {
        const openvdb::Vec3d w = g.transform().indexToWorld(openvdb::Vec3d(ijk[0], ijk[1], ijk[2]));
        for (int c = 0; c < 3; ++c) {
            const double expect = origin[c] + ijk[0] * axes[0][c] + ijk[1] * axes[1][c] + ijk[2] * axes[2][c];
            EXPECT_NEAR(w[c], expect, 1e-9 * (1 + std::abs(expect))) << what << " component " << c;
        }
    }
}

// Both routes: `import` -> .vdb, and `encode` -> .ssvdag -> `decode` -> .vdb.
void expectBothRoutes(const fs::path& input, const std::string& extraArgs, const Expected& e, const std::string& tag) {
    const fs::path vdb = workDir() / (tag + "_import.vdb"), ss = workDir() / (tag + ".ssvdag"), dec = workDir() / (tag + "_decoded.vdb");
    auto r = runCli("import " + input.string() + " " + extraArgs + " -o " + vdb.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    expectGridMatches(readOnlyGrid(vdb), e, tag + " import");
    r = runCli("encode " + input.string() + " " + extraArgs + " -o " + ss.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = runCli("decode " + ss.string() + " -o " + dec.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    expectGridMatches(readOnlyGrid(dec), e, tag + " encode+decode");
}

bool haveSharedData() { return fs::exists(denseDir() / "cranium_256x256x108_int16le.raw"); }

} // namespace

TEST(DenseSharedData, EveryScanRoundTripsExactly) {
    if (!haveSharedData()) GTEST_SKIP() << "shared data not present";
    struct Case {
        std::string header, data;
        std::array<int, 3> dims;
        std::string type;
        bool gzip;
    };
    const std::vector<Case> cases{
        {"cranium_256x256x108_int16le.nhdr", "cranium_256x256x108_int16le.raw", {256, 256, 108}, "i16", false},
        {"cthead_256x256x99_uint8.nhdr", "cthead_256x256x99_uint8.raw", {256, 256, 99}, "u8", false},
        {"headsq_64x64x93_int16le.mhd", "headsq_64x64x93_int16le.raw", {64, 64, 93}, "i16", false},
        {"tooth_103x94x161_uint8.mhd", "tooth_103x94x161_uint8.raw", {103, 94, 161}, "u8", false},
        {"neghip_64x64x64_uint8.raw", "neghip_64x64x64_uint8.raw", {64, 64, 64}, "u8", false},
        {"FLAIR.nrrd", "FLAIR.nrrd", {124, 160, 140}, "u8", true},
        {"fetal_template_T2.nrrd", "fetal_template_T2.nrrd", {117, 159, 126}, "f32", true},
    };
    for (const Case& c : cases) {
        size_t offset = 0;
        if (c.gzip) {  // attached data starts after the blank line ending the header
            const std::vector<uint8_t> all = readAll(denseDir() / c.data);
            const std::string text(all.begin(), all.begin() + 4096);
            offset = text.find("\n\n") + 2;
        }
        const Expected e = fromFile(denseDir() / c.data, offset, c.dims, c.type, false, c.gzip);
        expectBothRoutes(denseDir() / c.header, "", e, fs::path(c.header).stem().string());
    }
}

TEST(DenseSharedData, HeaderTransformsAndLosslessSizeBeatZstd) {
    if (!haveSharedData()) GTEST_SKIP() << "shared data not present";
    const fs::path ss = workDir() / "cranium_size.ssvdag";
    auto r = runCli("encode " + (denseDir() / "cranium_256x256x108_int16le.nhdr").string() + " -o " + ss.string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    // The lossless file must be below half the raw bytes (zstd -19 of the raw
    // file is 0.47x; scripts/dense_size_report.sh measures it in one run).
    EXPECT_LT(fs::file_size(ss), fs::file_size(denseDir() / "cranium_256x256x108_int16le.raw") * 47 / 100);
    // ... and below OpenVDB's own .vdb of the same dense grid (blosc, as `import` writes it).
    const fs::path craniumVdb = workDir() / "cranium_size.vdb";
    r = runCli("import " + (denseDir() / "cranium_256x256x108_int16le.nhdr").string() + " -o " + craniumVdb.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_LT(fs::file_size(ss), fs::file_size(craniumVdb));
    expectTransform(*readOnlyGrid(craniumVdb), {0, 0, 0}, {{{0.957, 0, 0}, {0, 0.957, 0}, {0, 0, 1.5}}}, {256, 256, 108}, "cranium");
    const fs::path vdb = workDir() / "flair.vdb";
    r = runCli("import " + (denseDir() / "FLAIR.nrrd").string() + " -o " + vdb.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    expectTransform(*readOnlyGrid(vdb), {64.898239135742202, 110.4311447143555, -27.92553901672364},
                    {{{-0.99359200921208746, 0.04970492721885441, -0.10151029228632795},
                      {-0.016005020190061219, -0.95093665139041228, -0.30897139733494045},
                      {-0.11188725988575336, -0.30536684015686016, 0.94563858529983524}}},
                    {124, 160, 140}, "FLAIR");
    r = runCli("import " + (denseDir() / "headsq_64x64x93_int16le.mhd").string() + " -o " + vdb.string() + " --force");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    expectTransform(*readOnlyGrid(vdb), {0, 0, 0}, {{{3.2, 0, 0}, {0, 3.2, 0}, {0, 0, 1.5}}}, {64, 64, 93}, "headsq");
}

TEST(DenseSynthetic, BigEndianRawWithOddSpacing) {
    const std::array<int, 3> dims{13, 7, 9};  // not multiples of 4: partial bricks
    std::vector<uint8_t> be;
    std::mt19937 rng(5);
    for (int i = 0; i < dims[0] * dims[1] * dims[2]; ++i) {
        const int16_t v = int16_t(rng() % 65536);
        be.push_back(uint8_t(uint16_t(v) >> 8));
        be.push_back(uint8_t(v & 0xFF));
    }
    const fs::path raw = workDir() / "odd.raw";
    writeBytes(raw, be.data(), be.size());
    const Expected e = fromFile(raw, 0, dims, "i16", true);
    expectBothRoutes(raw, "--dims 13 7 9 --type i16 --endian big --spacing 0.3 1.7 2.5 --origin -4 5 6.5", e, "odd_raw");
    expectTransform(*readOnlyGrid(workDir() / "odd_raw_decoded.vdb"), {-4, 5, 6.5}, {{{0.3, 0, 0}, {0, 1.7, 0}, {0, 0, 2.5}}}, dims, "raw");
}

TEST(DenseSynthetic, ObliqueBigEndianNhdrWithByteSkip) {
    const std::array<int, 3> dims{9, 6, 5};
    std::vector<uint8_t> data(7, 0xAB);  // 7 bytes to skip
    std::mt19937 rng(7);
    for (int i = 0; i < dims[0] * dims[1] * dims[2]; ++i) {
        const uint16_t v = uint16_t(rng() % 4096);
        data.push_back(uint8_t(v >> 8));
        data.push_back(uint8_t(v & 0xFF));
    }
    const fs::path dataPath = workDir() / "oblique.data", header = workDir() / "oblique.nhdr";
    writeBytes(dataPath, data.data(), data.size());
    std::ofstream(header) << "NRRD0005\n# oblique, big-endian\ntype: unsigned short\ndimension: 3\nspace: left-posterior-superior\n"
                             "sizes: 9 6 5\nspace directions: (0.6,0.8,0) (-1.6,1.2,0) (0,0,-2.5)\nspace origin: (10.5,-3,7)\n"
                             "endian: big\nencoding: raw\nbyte skip: 7\ndata file: oblique.data\n";
    const Expected e = fromFile(dataPath, 7, dims, "u16", true);
    expectBothRoutes(header, "", e, "oblique");
    expectTransform(*readOnlyGrid(workDir() / "oblique_decoded.vdb"), {10.5, -3, 7}, {{{0.6, 0.8, 0}, {-1.6, 1.2, 0}, {0, 0, -2.5}}}, dims, "nhdr");
}

TEST(DenseSynthetic, GzipNrrdFloatsBitExact) {
    const std::array<int, 3> dims{8, 5, 6};
    std::vector<uint8_t> be;
    std::mt19937 rng(11);
    std::vector<float> values;
    for (int i = 0; i < dims[0] * dims[1] * dims[2]; ++i) values.push_back(std::ldexp(float(int(rng() % 2001) - 1000), int(rng() % 20) - 10));
    values[0] = -0.0f;
    values[1] = std::numeric_limits<float>::quiet_NaN();
    values[2] = std::numeric_limits<float>::denorm_min();
    values[3] = -std::numeric_limits<float>::infinity();
    for (float f : values) {
        uint32_t u;
        std::memcpy(&u, &f, 4);
        for (int b = 3; b >= 0; --b) be.push_back(uint8_t(u >> (8 * b)));
    }
    const std::vector<uint8_t> gz = gzipBytes(be);
    const std::string header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 8 5 6\nspacings: 1.25 1.25 0.75\nendian: big\nencoding: gzip\n\n";
    const fs::path nrrd = workDir() / "floats.nrrd";
    writeBytes(nrrd, gz.data(), gz.size(), header);
    const Expected e = fromFile(nrrd, header.size(), dims, "f32", true, true);
    expectBothRoutes(nrrd, "", e, "gzip_floats");
    expectTransform(*readOnlyGrid(workDir() / "gzip_floats_import.vdb"), {0, 0, 0}, {{{1.25, 0, 0}, {0, 1.25, 0}, {0, 0, 0.75}}}, dims, "gzip");
}

// A float32 scan whose samples are all integers (a label map, a series
// saved as float) has the lattice of slope 1 as its rescale hint, in memory
// and cube by cube, and its values are coded as those integers: its file is
// the size of the same samples stored as int16 (to 2 %), well under the same
// floats with one sample off the integers, and comes back bit for bit
// (OpenVDB's accessor against the samples written). A -0.0 among them, a
// half, a NaN, an infinity or 2^31, and there is no hint (in memory or cube
// by cube), every sample still back bit for bit.
TEST(DenseSynthetic, FloatSamplesThatAreIntegersAreCodedAsIntegers) {
    using namespace vdbdag;
    const std::array<int, 3> dims{40, 36, 30};
    const size_t n = size_t(dims[0]) * dims[1] * dims[2];
    std::mt19937 rng(7);
    std::vector<float> floats(n);
    std::vector<int16_t> ints(n);
    for (int z = 0, i = 0; z < dims[2]; ++z)
        for (int y = 0; y < dims[1]; ++y)
            for (int x = 0; x < dims[0]; ++x, ++i) {
                ints[size_t(i)] = int16_t(800 + 400 * std::sin(x / 7.0) * std::cos(y / 5.0) + 10 * z + int(rng() % 17));
                floats[size_t(i)] = float(ints[size_t(i)]);
            }
    const auto write = [&](const std::string& stem, const void* data, size_t bytes, const std::string& type) {
        writeBytes(workDir() / (stem + ".raw"), data, bytes);
        const std::string h = "NRRD0004\ntype: " + type + "\ndimension: 3\nsizes: 40 36 30\nendian: little\nencoding: raw\ndata file: " + stem + ".raw\n";
        writeBytes(workDir() / (stem + ".nhdr"), h.data(), h.size());
        return workDir() / (stem + ".nhdr");
    };
    const auto encodedSize = [&](const fs::path& in) {
        const fs::path out = workDir() / (in.stem().string() + ".ssvdag");
        const auto r = runCli("encode " + in.string() + " -o " + out.string() + " --force");
        EXPECT_EQ(r.exitCode, 0) << r.err;
        return fs::file_size(out);
    };
    const fs::path integral = write("integer_floats", floats.data(), n * 4, "float");
    for (const bool byCubes : {false, true}) {
        bridge::DenseImportOptions options;
        if (byCubes) options.cubesNear = workDir().string();
        const bridge::DenseImportResult r = bridge::importDense(integral.string(), options);
        const GridRecord& header = byCubes ? r.cubes.at(0)->header() : r.volume.grids.at(0);
        EXPECT_EQ(header.rescale, std::optional<ValueRescale>(ValueRescale{1, 0})) << "by cubes " << byCubes;
    }
    expectBothRoutes(integral, "", fromFile(workDir() / "integer_floats.raw", 0, dims, "f32", false), "integer_floats");
    const uint64_t asFloats = encodedSize(integral);
    const uint64_t asInt16 = encodedSize(write("integer_int16", ints.data(), n * 2, "int16"));
    EXPECT_LT(double(asFloats), 1.02 * double(asInt16)) << asFloats << " against " << asInt16;
    const std::array<std::pair<float, const char*>, 5> odds{{{-0.0f, "negative_zero"},
                                                            {0.5f, "half"},
                                                            {std::numeric_limits<float>::quiet_NaN(), "nan"},
                                                            {std::numeric_limits<float>::infinity(), "infinity"},
                                                            {0x1p31f, "two_to_31"}}};
    for (const auto& [odd, name] : odds) {
        std::vector<float> off = floats;
        off[n / 2] = odd;
        const fs::path in = write(std::string(name) + "_floats", off.data(), n * 4, "float");
        EXPECT_FALSE(bridge::importDense(in.string(), {}).volume.grids.at(0).rescale.has_value()) << name;
        bridge::DenseImportOptions cubes;
        cubes.cubesNear = workDir().string();
        EXPECT_FALSE(bridge::importDense(in.string(), cubes).cubes.at(0)->header().rescale.has_value()) << name << " by cubes";
        expectBothRoutes(in, "", fromFile(workDir() / (in.stem().string() + ".raw"), 0, dims, "f32", false), in.stem().string());
        if (odd == 0.5f) {
            EXPECT_LT(double(asFloats), 0.95 * double(encodedSize(in))) << "the same floats with one half";
        }
    }
}

TEST(DenseSynthetic, MetaImageObliqueBigEndianAndInlineMha) {
    const std::array<int, 3> dims{7, 8, 6};
    std::vector<uint8_t> be;
    std::mt19937 rng(13);
    for (int i = 0; i < dims[0] * dims[1] * dims[2]; ++i) {
        const uint32_t v = i == 0 ? 0xFFFFFFFFu : uint32_t(rng());  // needs the Int64 grid
        for (int b = 3; b >= 0; --b) be.push_back(uint8_t(v >> (8 * b)));
    }
    const fs::path raw = workDir() / "meta_u32.bin", mhd = workDir() / "meta_u32.mhd";
    writeBytes(raw, be.data(), be.size());
    // Rows of TransformMatrix are the axis directions (a rotation about z by 30 degrees).
    const double c30 = std::sqrt(3.0) / 2, s30 = 0.5;
    auto fmt_double = [](double v) {
        char b[64];
        std::snprintf(b, sizeof b, "%.17g", v);
        return std::string(b);
    };
    std::ofstream(mhd) << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = True\nCompressedData = False\n"
                       << "TransformMatrix = " << fmt_double(c30) << " 0.5 0 -0.5 " << fmt_double(c30) << " 0 0 0 1\n"
                       << "Offset = 1.5 -2 3\nElementSpacing = 0.4 0.9 3.1\nDimSize = 7 8 6\nElementType = MET_UINT\n"
                       << "ElementDataFile = meta_u32.bin\n";
    const Expected e = fromFile(raw, 0, dims, "u32", true);
    expectBothRoutes(mhd, "", e, "meta_u32");
    expectTransform(*readOnlyGrid(workDir() / "meta_u32_decoded.vdb"), {1.5, -2, 3},
                    {{{0.4 * c30, 0.4 * s30, 0}, {-0.9 * s30, 0.9 * c30, 0}, {0, 0, 3.1}}}, dims, "mhd");

    // .mha with the samples inline (LOCAL), signed bytes.
    std::vector<uint8_t> bytes;
    for (int i = 0; i < 5 * 4 * 3; ++i) bytes.push_back(uint8_t(rng()));
    const std::string header = "ObjectType = Image\nNDims = 3\nDimSize = 5 4 3\nElementSpacing = 2 2 2\nElementType = MET_CHAR\nElementDataFile = LOCAL\n";
    const fs::path mha = workDir() / "inline.mha";
    writeBytes(mha, bytes.data(), bytes.size(), header);
    expectBothRoutes(mha, "", fromFile(mha, header.size(), {5, 4, 3}, "i8", false), "inline_mha");
}

TEST(DenseErrors, MalformedInputsGiveOneLineErrorsAndNoOutput) {
    const fs::path d = workDir() / "bad";
    fs::create_directories(d);
    std::vector<uint8_t> zeros(4 * 4 * 4 * 2, 0);
    writeBytes(d / "data.raw", zeros.data(), zeros.size());
    writeBytes(d / "short.raw", zeros.data(), zeros.size() - 3);
    const std::string good = "NRRD0004\ntype: int16\ndimension: 3\nsizes: 4 4 4\nendian: little\nencoding: raw\n";
    struct Case {
        std::string name, text, expect;  // expect: part of the message
    };
    const std::vector<Case> cases{
        {"nodata.nhdr", good + "data file: missing.raw\n", "does not exist"},
        {"short.nhdr", good + "data file: short.raw\n", "too short"},
        {"int64.nhdr", "NRRD0004\ntype: int64\ndimension: 3\nsizes: 4 4 4\nendian: little\nencoding: raw\ndata file: data.raw\n", "unsupported NRRD type"},
        {"magic.nhdr", "NRRX0004\n", "not a NRRD file"},
        {"nosizes.nhdr", "NRRD0004\ntype: int16\ndimension: 3\nendian: little\nencoding: raw\ndata file: data.raw\n", "'sizes'"},
        {"dim2.nhdr", "NRRD0004\ntype: int16\ndimension: 2\nsizes: 4 4\nendian: little\nencoding: raw\ndata file: data.raw\n", "dimension 2"},
        {"spacing.nhdr", good + "spacings: 1 abc 1\ndata file: data.raw\n", "not a finite number"},
        {"zero.nhdr", good + "spacings: 1 0 1\ndata file: data.raw\n", "degenerate"},
        {"bzip.nhdr", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 4 4 4\nendian: little\nencoding: bzip2\ndata file: data.raw\n", "bzip2"},
        {"noendian.nhdr", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 4 4 4\nencoding: raw\ndata file: data.raw\n", "endian"},
        {"huge.nhdr", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 100000 100000 100000\nendian: little\nencoding: raw\ndata file: data.raw\n", "absurd"},
        {"gzbad.nhdr", "NRRD0004\ntype: int16\ndimension: 3\nsizes: 4 4 4\nendian: little\nencoding: gzip\ndata file: data.raw\n", "compressed data"},
        {"nofile.mhd", "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_SHORT\n", "no ElementDataFile"},
        {"long.mhd", "NDims = 3\nDimSize = 4 4 4\nElementType = MET_LONG\nElementDataFile = data.raw\n", "MET_LONG"},
        {"channels.mhd", "NDims = 3\nDimSize = 4 4 4\nElementNumberOfChannels = 4\nElementType = MET_SHORT\nElementDataFile = data.raw\n", "Channels"},
        {"shortmhd.mhd", "NDims = 3\nDimSize = 4 4 4\nElementType = MET_SHORT\nElementDataFile = short.raw\n", "too short"},
        {"nanspacing.mhd", "NDims = 3\nDimSize = 4 4 4\nElementSpacing = 1 nan 1\nElementType = MET_SHORT\nElementDataFile = data.raw\n", "finite"},
    };
    for (const Case& c : cases) {
        std::ofstream(d / c.name) << c.text;
        for (const std::string verb : {"import", "encode"}) {
            const fs::path out = d / (c.name + (verb == "import" ? ".vdb" : ".ssvdag"));
            const auto r = runCli(verb + " " + (d / c.name).string() + " -o " + out.string());
            EXPECT_NE(r.exitCode, 0) << c.name;
            EXPECT_NE(r.err.find(c.name), std::string::npos) << c.name << ": " << r.err;
            EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.name << ": " << r.err;
            EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.name << ": " << r.err;
            EXPECT_FALSE(fs::exists(out)) << c.name;
        }
    }
    // Raw files: a size that does not match, and no layout at all.
    for (const auto& [args, expect] : std::vector<std::pair<std::string, std::string>>{
             {(d / "data.raw").string() + " --dims 4 4 5 --type i16", "holds 128 bytes"},
             {(d / "data.raw").string(), "needs its layout"},
             {(d / "data.raw").string() + " --dims 4 4 4 --type i64", "unsupported sample type"},
             {(d / "missing.raw").string() + " --dims 4 4 4 --type u8", "no such file"}}) {
        const auto r = runCli("import " + args + " -o " + (d / "raw.vdb").string());
        EXPECT_NE(r.exitCode, 0) << args;
        EXPECT_NE(r.err.find(expect), std::string::npos) << args << ": " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(fs::exists(d / "raw.vdb"));
    }
}

TEST(DenseThreshold, BackgroundBelowReportsTheExactCost) {
    // Synthetic noisy "air" (values around 100) and an object (around 2000).
    const std::array<int, 3> dims{24, 20, 16};
    std::vector<int16_t> v;
    std::mt19937 rng(3);
    for (int z = 0; z < dims[2]; ++z)
        for (int y = 0; y < dims[1]; ++y)
            for (int x = 0; x < dims[0]; ++x) {
                const bool inside = (x - 12) * (x - 12) + (y - 10) * (y - 10) + (z - 8) * (z - 8) < 36;
                v.push_back(int16_t((inside ? 2000 : 100) + int(rng() % 61) - 30));
            }
    const fs::path raw = workDir() / "thr_24x20x16_int16le.raw";
    writeBytes(raw, v.data(), v.size() * 2);
    const fs::path out = workDir() / "thr.vdb";
    const auto r = runCli("import " + raw.string() + " --background-below 500 --json -o " + out.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto report = nlohmann::json::parse(r.out)["threshold"];
    // Brute force: removed samples, their rounded mean, the changes.
    uint64_t removed = 0;
    double sum = 0, mn = 1e9, mx = -1e9;
    for (int16_t s : v) {
        mn = std::min(mn, double(s));
        mx = std::max(mx, double(s));
        if (s < 500) { ++removed; sum += s; }
    }
    const double background = double(std::llround(sum / double(removed)));
    double maxAbs = 0, sumAbs = 0, sumSq = 0;
    uint64_t changed = 0;
    for (int16_t s : v)
        if (s < 500) {
            const double c = std::abs(s - background);
            changed += c != 0;
            maxAbs = std::max(maxAbs, c);
            sumAbs += c;
            sumSq += c * c;
        }
    const double mse = sumSq / double(v.size());
    EXPECT_EQ(report["inactive_samples"].get<uint64_t>(), removed);
    EXPECT_EQ(report["changed_samples"].get<uint64_t>(), changed);
    EXPECT_EQ(report["background_value"].get<double>(), background);
    EXPECT_EQ(report["max_abs_change"].get<double>(), maxAbs);
    EXPECT_NEAR(report["mean_abs_change"].get<double>(), sumAbs / double(v.size()), 1e-9);
    EXPECT_NEAR(report["psnr_db"].get<double>(), 10 * std::log10((mx - mn) * (mx - mn) / mse), 1e-9);
    // The grid, from `import` and from `encode` + `decode`: kept samples
    // active and exact, the rest inactive background.
    const fs::path ss = workDir() / "thr.ssvdag", dec = workDir() / "thr_decoded.vdb";
    ASSERT_EQ(runCli("encode " + raw.string() + " --background-below 500 -o " + ss.string()).exitCode, 0);
    ASSERT_EQ(runCli("decode " + ss.string() + " -o " + dec.string()).exitCode, 0);
    for (const fs::path& file : {out, dec}) {
        auto grid = openvdb::gridPtrCast<openvdb::Int32Grid>(readOnlyGrid(file));
        ASSERT_TRUE(grid) << file;
        EXPECT_EQ(grid->background(), int(background));
        EXPECT_EQ(grid->activeVoxelCount(), v.size() - removed);
        auto acc = grid->getConstAccessor();
        size_t bad = 0;
        for (int z = 0; z < dims[2]; ++z)
            for (int y = 0; y < dims[1]; ++y)
                for (int x = 0; x < dims[0]; ++x) {
                    const int16_t s = v[(size_t(z) * dims[1] + y) * dims[0] + x];
                    const openvdb::Coord c(x, y, z);
                    if (s < 500) bad += acc.isValueOn(c) || acc.getValue(c) != int(background);
                    else bad += !acc.isValueOn(c) || acc.getValue(c) != s;
                }
        EXPECT_EQ(bad, 0u) << file;
    }
}

TEST(PredictedChannel, RoundTripsIntegersExactlyAndRejectsCorruption) {
    std::mt19937_64 rng(17);
    std::vector<uint64_t> layout;
    uint64_t entries = 0;
    for (int i = 0; i < 300; ++i) {
        const uint64_t mask = (i % 7 == 0) ? 0 : (i % 3 == 0 ? ~uint64_t(0) : rng());
        layout.push_back(mask);
        entries += mask ? uint64_t(std::popcount(mask)) : 1;
    }
    for (const uint32_t vs : {4u, 8u}) {
        std::vector<uint8_t> values(entries * vs);
        for (uint64_t e = 0; e < entries; ++e) {
            uint64_t v = (e % 11 == 0) ? rng() : uint64_t(int64_t(1000 + int(rng() % 9)));  // extremes and smooth runs
            if (e == 5) v = vs == 4 ? 0x80000000u : 0x8000000000000000ull;
            if (e == 6) v = vs == 4 ? 0x7FFFFFFFu : 0x7FFFFFFFFFFFFFFFull;
            std::memcpy(&values[e * vs], &v, vs);
        }
        const auto payload = vdbdag::attributes::encodePredicted(values, vs, layout);
        EXPECT_EQ(vdbdag::attributes::decodePredicted(payload, vs, layout, "test"), values);
        auto truncated = payload;
        truncated.pop_back();
        EXPECT_THROW(vdbdag::attributes::decodePredicted(truncated, vs, layout, "test"), vdbdag::Error);
        auto badPredictor = payload;
        badPredictor[0] = 9;
        EXPECT_THROW(vdbdag::attributes::decodePredicted(badPredictor, vs, layout, "test"), vdbdag::Error);
        auto shortLayout = layout;
        shortLayout.pop_back();
        EXPECT_THROW(vdbdag::attributes::decodePredicted(payload, vs, shortLayout, "test"), vdbdag::Error);
    }
}

TEST(PredictedChannel, SurvivesTheFileWithMirroredBricksAndTiles) {
    // Bricks whose masks repeat under reflections, so the DAG stores mirrored
    // instances, plus a tile; int32 values smooth enough that the predictor wins.
    using namespace vdbdag;
    GridRecord record;
    record.name = "ints";
    record.valueType = ValueType::Int32;
    record.background = {0, 0, 0, 0};
    record.vdbDescriptor = {1, 2, 3};
    std::mt19937 rng(23);
    for (int i = 0; i < 64; ++i) {
        // Even i: the z = 0 plane plus one voxel at z = 1; odd i: its mirror
        // image in z (the z = 3 plane plus the same voxel at z = 2).
        const int k = (i / 2) % 16;
        const uint64_t mask = (i % 2) ? (0xFFFF000000000000ull | (uint64_t(1) << (32 + k))) : (0xFFFFull | (uint64_t(1) << (16 + k)));
        record.topology.bricks.push_back({4 * (i % 8), 4 * (i / 8), 0, mask});
    }
    record.topology.tiles.push_back({64, 0, 0, 3});
    std::map<std::array<int32_t, 3>, std::vector<int32_t>> expected;
    for (const Brick& b : record.topology.bricks) {
        auto& vals = expected[{b.x, b.y, b.z}];
        for (int k = 0; k < std::popcount(b.mask); ++k) {
            const int32_t v = 2000 + b.x * 10 + b.y * 3 + k * 2 + int32_t(rng() % 3);
            vals.push_back(v);
            const auto* p = reinterpret_cast<const uint8_t*>(&v);
            record.values.bricks.insert(record.values.bricks.end(), p, p + 4);
        }
    }
    const int32_t tileValue = -123456;
    const auto* tp = reinterpret_cast<const uint8_t*>(&tileValue);
    record.values.tiles.assign(tp, tp + 4);

    format::SsvdagScene scene;
    scene.grids.push_back(pipeline::encodeGrid(record));
    {  // one predicted window, coded by the context-modelled predictor with its bricks placed and its tile a neighbour (coding 19), not palettes
        const attributes::ValueWindowsPayload& w = scene.grids[0].active.valueWindows;
        ASSERT_TRUE(w.predicted);
        const auto dir = attributes::readPredictedWindowDirectory(w.bytes, 4, encoding::attributeLayout(scene.grids[0].active.dag), "test");
        ASSERT_EQ(dir.windows.size(), 1u);
        EXPECT_EQ(attributes::windowRawBytes(w.bytes, dir.windows[0], "test").at(0), attributes::detail::kTiledContextCoding)
            << "the predictor should win on this channel";
    }
    EXPECT_LT(scene.grids[0].active.dag.leaves.size(), 16u) << "32 distinct masks, pairs of mirror images: reflected instances must exist";
    const auto bytes = format::writeScene(scene);
    const format::SsvdagScene back = format::readScene(bytes, "mem");
    const GridRecord decoded = pipeline::decodeGrid(back.grids[0]);
    ASSERT_EQ(decoded.topology.bricks.size(), record.topology.bricks.size());
    size_t next = 0;
    for (const Brick& b : decoded.topology.bricks) {
        const auto it = expected.find({b.x, b.y, b.z});
        ASSERT_NE(it, expected.end());
        for (int32_t want : it->second) {
            int32_t got;
            std::memcpy(&got, &decoded.values.bricks[4 * next++], 4);
            EXPECT_EQ(got, want);
        }
    }
    ASSERT_EQ(decoded.values.tiles.size(), 4u);
    int32_t gotTile;
    std::memcpy(&gotTile, decoded.values.tiles.data(), 4);
    EXPECT_EQ(gotTile, tileValue);
    // The palettes (the traceable layout) built from them agree entry by entry.
    EXPECT_EQ(format::traceableValues(back.grids[0]).decodeAll(), back.grids[0].active.attributes);
}
