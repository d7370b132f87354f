// Dense scans read cube by cube (vdb_bridge/DenseCubes.cpp: the samples in
// a scratch file, DenseImport.h's cubesNear): the cube source's bricks and
// values are the in-memory import's (compared brick by brick), and
// `encode --memory-limit` (any limit, one thread, mpirun) writes the bytes
// of the in-memory encode, on synthetic scans with odd extents, thresholds
// and gzip data, and on the shared scans (CT, NIfTI with a rescale, a DICOM
// series missing a slice) when present. The decoded samples are checked
// against the raw file read here.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include <openvdb/openvdb.h>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/DenseImport.h"

namespace fs = std::filesystem;
using vdbdag::testing::runCli;
using vdbdag::testing::runShell;

namespace {

fs::path workDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_dense_cubes_" + std::to_string(getpid()));
        fs::remove_all(d);
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

// 37 x 29 x 23 int16 samples (partial bricks on three faces): "air" around
// 100 with noise and an object around 2000.
std::vector<int16_t> noisyObject() {
    std::vector<int16_t> v;
    std::mt19937 rng(11);
    for (int z = 0; z < 23; ++z)
        for (int y = 0; y < 29; ++y)
            for (int x = 0; x < 37; ++x) {
                const bool inside = (x - 18) * (x - 18) + (y - 14) * (y - 14) + (z - 11) * (z - 11) < 81;
                v.push_back(int16_t((inside ? 2000 : 100) + int(rng() % 61) - 30));
            }
    return v;
}

fs::path writeRaw(const std::vector<int16_t>& v) {
    const fs::path raw = workDir() / "object_37x29x23_int16le.raw";
    std::ofstream(raw, std::ios::binary).write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * 2));
    return raw;
}

struct BrickKey {
    int32_t x, y, z;
    bool operator<(const BrickKey& o) const { return std::tie(z, y, x) < std::tie(o.z, o.y, o.x); }
    bool operator==(const BrickKey&) const = default;
};
// Each brick's mask and values, keyed by its corner.
std::map<BrickKey, std::pair<uint64_t, std::vector<uint8_t>>> bricksOf(const vdbdag::GridTopology& t, const vdbdag::LayerValues& values, unsigned vs) {
    std::map<BrickKey, std::pair<uint64_t, std::vector<uint8_t>>> out;
    size_t at = 0;
    for (const vdbdag::Brick& b : t.bricks) {
        const size_t n = size_t(std::popcount(b.mask)) * vs;
        out[{b.x, b.y, b.z}] = {b.mask, std::vector<uint8_t>(values.bricks.begin() + long(at), values.bricks.begin() + long(at + n))};
        at += n;
    }
    return out;
}

// encode IN -o default, then with each of `variants` (extra options): cmp.
void expectSameBytes(const std::string& input, const std::string& name, const std::string& extra = "") {
    const fs::path whole = workDir() / (name + "_whole.ssvdag");
    const auto w = runCli("encode " + input + " " + extra + " -o " + whole.string() + " -f");
    ASSERT_EQ(w.exitCode, 0) << w.err;
    for (const std::string variant : {"--memory-limit 1M", "--memory-limit 64K --threads 1"}) {
        const fs::path out = workDir() / (name + "_cubes.ssvdag");
        const auto r = runCli("encode " + input + " " + extra + " " + variant + " -o " + out.string() + " -f");
        ASSERT_EQ(r.exitCode, 0) << variant << ": " << r.err;
        EXPECT_EQ(runShell("cmp " + whole.string() + " " + out.string()).exitCode, 0) << name << " " << variant;
    }
    for (const auto& e : fs::directory_iterator(workDir()))
        EXPECT_EQ(e.path().string().find(".scratch"), std::string::npos) << "scratch file left: " << e.path();
}

} // namespace

TEST(DenseCubes, TheCubeSourceHoldsTheImportsBricksAndValues) {
    const std::vector<int16_t> v = noisyObject();
    const fs::path raw = writeRaw(v);
    for (const bool threshold : {false, true}) {
        SCOPED_TRACE(threshold ? "--background-below 500" : "no threshold");
        vdbdag::bridge::DenseImportOptions options;
        options.showProgress = false;
        if (threshold) options.backgroundBelow = 500;
        const vdbdag::bridge::DenseImportResult whole = vdbdag::bridge::importDense(raw.string(), options);
        options.cubesNear = (workDir() / "x").string();
        vdbdag::bridge::DenseImportResult cubes = vdbdag::bridge::importDense(raw.string(), options);
        ASSERT_EQ(cubes.cubes.size(), 1u);
        ASSERT_EQ(whole.volume.grids.size(), 1u);
        const vdbdag::GridRecord& record = whole.volume.grids[0];
        EXPECT_TRUE(cubes.volume.grids[0].topology.bricks.empty());  // the voxels are in the scratch file
        EXPECT_EQ(cubes.volume.grids[0].vdbDescriptor, record.vdbDescriptor);  // the threshold report's metadata too
        vdbdag::CubeSource& source = *cubes.cubes[0];
        const vdbdag::LayerSummary s = source.summary(vdbdag::Layer::Active);
        EXPECT_EQ(s.voxels, record.topology.activeVoxelCount());
        EXPECT_EQ(s.bricks, record.topology.bricks.size());
        const auto expected = bricksOf(record.topology, record.values, 4);
        for (const unsigned log2 : {3u, 4u, 6u}) {
            const std::array<int64_t, 3> origin{-8, -4, 0};
            std::vector<vdbdag::CubeLoad> loads = source.cubes(vdbdag::Layer::Active, origin, log2);
            source.beginPass(vdbdag::Layer::Active, origin, log2, true);
            std::map<BrickKey, std::pair<uint64_t, std::vector<uint8_t>>> got;
            for (const vdbdag::CubeLoad& load : loads) {
                vdbdag::GridTopology t;
                vdbdag::LayerValues values;
                source.read(load.cell, t, values);
                EXPECT_EQ(t.bricks.size(), load.bricks) << "cube size 2^" << log2;
                for (auto& [key, brick] : bricksOf(t, values, 4)) EXPECT_TRUE(got.emplace(key, brick).second) << "a brick read twice";
            }
            source.endPass();
            EXPECT_TRUE(got == expected) << "cube size 2^" << log2;
        }
    }
}

TEST(DenseCubes, MemoryLimitGivesTheInMemoryBytes) {
    const std::vector<int16_t> v = noisyObject();
    const fs::path raw = writeRaw(v);
    expectSameBytes(raw.string(), "raw");
    expectSameBytes(raw.string(), "raw_threshold", "--background-below 500");
    // The limited encode decodes to the raw samples (read here, not by the project's reader).
    const fs::path limited = workDir() / "raw_limited.ssvdag", decoded = workDir() / "raw_limited.vdb";
    ASSERT_EQ(runCli("encode " + raw.string() + " --memory-limit 64K -o " + limited.string()).exitCode, 0);
    ASSERT_EQ(runCli("decode " + limited.string() + " -o " + decoded.string()).exitCode, 0);
    openvdb::initialize();
    openvdb::io::File file(decoded.string());
    file.open();
    auto grid = openvdb::gridPtrCast<openvdb::Int32Grid>(file.readGrid(file.beginName().gridName()));
    ASSERT_TRUE(grid);
    EXPECT_EQ(grid->activeVoxelCount(), v.size());
    auto acc = grid->getConstAccessor();
    size_t bad = 0;
    for (int z = 0; z < 23; ++z)
        for (int y = 0; y < 29; ++y)
            for (int x = 0; x < 37; ++x) bad += acc.getValue({x, y, z}) != v[(size_t(z) * 29 + size_t(y)) * 37 + size_t(x)];
    EXPECT_EQ(bad, 0u);
}

TEST(DenseCubes, SharedScansGiveTheInMemoryBytes) {
    const fs::path data(VDBDAG_SHARED_DATA);
    std::vector<std::pair<fs::path, std::string>> inputs{
        {data / "dense" / "cranium_256x256x108_int16le.nhdr", ""},   // CT: predicted windows
        {data / "dense" / "FLAIR.nrrd", ""},                         // gzip NRRD
        {data / "medical" / "nifti" / "avf_float_32.nii.gz", ""},    // floats
        {data / "medical" / "nifti" / "labels256.nii.gz", ""},       // labels: palette windows
        {data / "medical" / "dicom" / "adi_brain", "--series 1.3.12.2.1107.5.2.32.35235.2012041417312491079284166.0.0.0"},  // a missing slice
        {data / "dense" / "cthead_256x256x99_uint8.nhdr", "--background-below 40"}};
    size_t tried = 0;
    for (const auto& [input, extra] : inputs) {
        if (!fs::exists(input)) continue;
        SCOPED_TRACE(input.string());
        expectSameBytes(input.string(), input.stem().string(), extra);
        ++tried;
    }
    if (!tried) GTEST_SKIP() << "no shared scans in " << data;
}

TEST(DenseCubes, MpirunGivesTheSingleProcessBytes) {
#if !defined(VDBDAG_MPI_BINARY)
    GTEST_SKIP() << "vdbdag-mpi not built (no MPI found)";
#else
    const fs::path raw = writeRaw(noisyObject());
    const fs::path single = workDir() / "mpi_single.ssvdag", out = workDir() / "mpi_np2.ssvdag";
    ASSERT_EQ(runCli("encode " + raw.string() + " --background-below 500 -o " + single.string() + " -f").exitCode, 0);
    const std::string command = std::string(VDBDAG_MPIRUN) + " --oversubscribe --allow-run-as-root -np 2 " + VDBDAG_MPI_BINARY + " encode " +
                                raw.string() + " --background-below 500 -o " + out.string() + " -f --memory-limit 1M";
    const auto run = runShell(command);
    ASSERT_EQ(run.exitCode, 0) << command << "\n" << run.err;
    EXPECT_EQ(runShell("cmp " + single.string() + " " + out.string()).exitCode, 0);
#endif
}

// decode to a scan file goes cube by cube from the DAG (DenseExport.h's
// exportDenseByCubes): every raw-encoded format gives the samples back,
// checked against the raw file read here; .nii (by cubes) and .nii.gz (the
// whole-grid writer) hold the same bytes once inflated.
TEST(DenseCubes, DecodeWritesTheScanCubeByCube) {
    const std::vector<int16_t> v = noisyObject();
    const fs::path raw = writeRaw(v);
    const fs::path ss = workDir() / "decode.ssvdag";
    ASSERT_EQ(runCli("encode " + raw.string() + " --memory-limit 64K -o " + ss.string() + " -f").exitCode, 0);
    const fs::path back = workDir() / "decode_back.raw";
    const auto r = runCli("decode " + ss.string() + " -o " + back.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(runShell("cmp " + raw.string() + " " + back.string()).exitCode, 0);
    for (const std::string ext : {".nrrd", ".nhdr", ".mha", ".mhd", ".nii"}) {
        const fs::path out = workDir() / ("decode_back" + ext);
        const auto d = runCli("decode " + ss.string() + " -o " + out.string() + " -f");
        ASSERT_EQ(d.exitCode, 0) << ext << ": " << d.err;
        // The samples are the last bytes of the data file.
        const fs::path data = (ext == ".nhdr" || ext == ".mhd") ? workDir() / "decode_back.raw" : out;
        EXPECT_EQ(runShell("cmp -i " + std::to_string(fs::file_size(data) - fs::file_size(raw)) + ":0 " + data.string() + " " + raw.string()).exitCode, 0) << ext;
    }
    const fs::path gz = workDir() / "decode_back.nii.gz";
    ASSERT_EQ(runCli("decode " + ss.string() + " -o " + gz.string() + " -f").exitCode, 0);
    EXPECT_EQ(runShell("gzip -dc " + gz.string() + " | cmp - " + (workDir() / "decode_back.nii").string()).exitCode, 0);

    // Thresholds: the removed samples come back as the background (their
    // rounded mean, not 0: the whole file is first filled with it).
    const fs::path thr = workDir() / "decode_threshold.ssvdag", thrBack = workDir() / "decode_threshold.raw";
    ASSERT_EQ(runCli("encode " + raw.string() + " --background-below 500 --memory-limit 64K -o " + thr.string() + " -f").exitCode, 0);
    ASSERT_EQ(runCli("decode " + thr.string() + " -o " + thrBack.string() + " -f").exitCode, 0);
    double sum = 0;
    uint64_t removed = 0;
    for (int16_t s : v)
        if (s < 500) sum += s, ++removed;
    const int16_t background = int16_t(std::llround(sum / double(removed)));
    ASSERT_NE(background, 0);
    std::vector<int16_t> got(v.size());
    std::ifstream(thrBack, std::ios::binary).read(reinterpret_cast<char*>(got.data()), std::streamsize(got.size() * 2));
    size_t bad = 0;
    for (size_t i = 0; i < v.size(); ++i) bad += got[i] != (v[i] < 500 ? background : v[i]);
    EXPECT_EQ(bad, 0u);
}
