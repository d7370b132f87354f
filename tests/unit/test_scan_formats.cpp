// NIfTI in, and every scan format back out (`decode -o X.nrrd|.nhdr|.mha|
// .mhd|.nii|.nii.gz|.raw`), checked against an independent reader:
// tests/tools/scan_reference.py (nibabel for NIfTI, small parsers written
// from the NRRD and MetaImage specifications) gives the stored samples and
// the LPS index-to-world matrix of both the input and what decode wrote;
// OpenVDB's accessor gives the values of .vdb grids written as scans.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;
using vdbdag::testing::CommandResult;
using vdbdag::testing::runCli;
using vdbdag::testing::runShell;

namespace {

const std::string kPython = "/usr/bin/python3";  // Debian's, where python3-nibabel lives (a pyenv python3 may come first on PATH)

fs::path workDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_scans_" + std::to_string(getpid()));
        fs::remove_all(d);
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

bool haveNibabel() {
    static const bool ok = runShell(kPython + " -c 'import nibabel, numpy' > /dev/null").exitCode == 0;
    return ok;
}

std::string readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

struct Reference {
    std::string error;
    std::array<int64_t, 3> dims{};
    std::string dtype;
    std::array<std::array<double, 4>, 4> lps{};
    double slope = 1, inter = 0;
    std::string samples;
};

Reference reference(const fs::path& scan, std::optional<int> volume = std::nullopt) {
    static int counter = 0;
    const fs::path out = workDir() / ("ref" + std::to_string(counter++));
    const CommandResult r = runShell(kPython + " " + (fs::path(__FILE__).parent_path().parent_path() / "tools" / "scan_reference.py").string() + " " + scan.string() + " " +
                                     out.string() + (volume ? " " + std::to_string(*volume) : ""));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    Reference ref;
    const nlohmann::json j = nlohmann::json::parse(readAll(out.string() + ".json"));
    if (j.contains("error")) {
        ref.error = j["error"];
        return ref;
    }
    for (int a = 0; a < 3; ++a) ref.dims[size_t(a)] = j["dims"][size_t(a)];
    ref.dtype = j["dtype"];
    for (int r0 = 0; r0 < 4; ++r0)
        for (int c = 0; c < 4; ++c) ref.lps[size_t(r0)][size_t(c)] = j["lps"][size_t(r0)][size_t(c)];
    ref.slope = j["slope"];
    ref.inter = j["inter"];
    ref.samples = readAll(out.string() + ".raw");
    fs::remove(out.string() + ".raw");
    return ref;
}

// Same samples, type and extent; the same LPS matrix to `tolerance` (NIfTI-1
// stores its sform as float).
void expectSameScan(const Reference& a, const Reference& b, double tolerance, const std::string& what) {
    ASSERT_TRUE(a.error.empty() && b.error.empty()) << what << ": " << a.error << " / " << b.error;
    EXPECT_EQ(a.dims, b.dims) << what;
    EXPECT_EQ(a.dtype, b.dtype) << what;
    EXPECT_TRUE(a.samples == b.samples) << what << ": samples differ (" << a.samples.size() << " vs " << b.samples.size() << " bytes)";
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) {
            const double scale = c == 3 ? 1.0 + std::abs(a.lps[size_t(r)][3]) : 1.0;
            EXPECT_NEAR(a.lps[size_t(r)][size_t(c)], b.lps[size_t(r)][size_t(c)], tolerance * scale) << what << " matrix (" << r << "," << c << ")";
        }
    EXPECT_DOUBLE_EQ(a.slope, b.slope) << what;
    EXPECT_DOUBLE_EQ(a.inter, b.inter) << what;
}

CommandResult encode(const fs::path& in, const fs::path& out, const std::string& extra = "") {
    return runCli("encode " + in.string() + " -o " + out.string() + " -f " + extra);
}

void expectOneLineError(const CommandResult& r, const std::string& mustName, const std::string& what) {
    EXPECT_EQ(r.exitCode, 1) << what << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << ": " << r.err;
    EXPECT_NE(r.err.find(mustName), std::string::npos) << what << ": " << r.err;
}

// Runs a nibabel script in a fresh folder `dir` (the script sees it as `d`);
// false, with the error reported, when the script fails.
bool runNibabel(const fs::path& dir, const std::string& body) {
    fs::create_directories(dir);
    const fs::path script = dir / "make.py";
    std::ofstream(script) << "import nibabel as nib, numpy as np, sys\nd = sys.argv[1]\n" << body;
    const CommandResult made = runShell(kPython + " " + script.string() + " " + dir.string());
    EXPECT_EQ(made.exitCode, 0) << made.err;
    return made.exitCode == 0;
}

fs::path niftiDir() { return fs::path(VDBDAG_SHARED_DATA) / "medical" / "nifti"; }
fs::path denseDir() { return fs::path(VDBDAG_SHARED_DATA) / "dense"; }

} // namespace

// Every shared NIfTI file is read as nibabel reads it (stored samples, the
// sform/qform nibabel picks, in LPS) - shown by writing it back as NRRD and
// reading both with the reference - or refused in one line naming the file.
TEST(ScanFormats, EveryNiftiFileReadsAsNibabelDoes) {
    if (!fs::exists(niftiDir()) || !haveNibabel()) GTEST_SKIP() << "needs ../shared/data/medical and python3-nibabel";
    int read = 0, refused = 0;
    for (const auto& entry : fs::directory_iterator(niftiDir())) {
        const fs::path in = entry.path();
        const std::string name = in.filename().string();
        const Reference ref = reference(in);
        const fs::path ss = workDir() / "nifti.ssvdag";
        const CommandResult r = encode(in, ss);
        if (ref.error == "4-D") {  // one grid per volume: checked below
            ASSERT_EQ(r.exitCode, 0) << name << ": " << r.err;
            fs::remove(ss);
            ++read;
            continue;
        }
        if (!ref.error.empty()) {
            expectOneLineError(r, in.string(), name);
            EXPECT_FALSE(fs::exists(ss)) << name;
            ++refused;
            continue;
        }
        ASSERT_EQ(r.exitCode, 0) << name << ": " << r.err;
        const fs::path back = workDir() / "nifti_back.nrrd";
        // NRRD has no rescale field: a rescaled file (shear.nii.gz) gives its
        // values there by default (tests/python/test_scans_faithful.py), its
        // stored samples with --stored-values, compared here.
        const bool rescaled = ref.slope != 1 || ref.inter != 0;
        const CommandResult d = runCli("decode " + ss.string() + " -o " + back.string() + " -f" + (rescaled ? " --stored-values" : ""));
        ASSERT_EQ(d.exitCode, 0) << name << ": " << d.err;
        Reference got = reference(back);
        got.slope = ref.slope;  // the rescale is in key/value pairs the reference does not read
        got.inter = ref.inter;
        expectSameScan(ref, got, 1e-9, name);
        fs::remove(ss);
        ++read;
    }
    EXPECT_GE(read, 10);
    EXPECT_GE(refused, 1);  // complex64

    const fs::path series = niftiDir() / "mpld_asl.nii.gz";
    if (fs::exists(series)) {
        const fs::path ss = workDir() / "asl.ssvdag", back = workDir() / "asl.nii.gz";
        ASSERT_EQ(encode(series, ss, "--volume 7").exitCode, 0);
        ASSERT_EQ(runCli("decode " + ss.string() + " -o " + back.string() + " -f").exitCode, 0);
        expectSameScan(reference(series, 7), reference(back), 1e-6, "mpld_asl volume 7");
        expectOneLineError(encode(series, ss, "--volume 25"), "out of range", "--volume 25");
        // Without --volume: one grid per volume, NAME_tN, each nibabel's volume N.
        ASSERT_EQ(encode(series, ss).exitCode, 0);
        const CommandResult info = runCli("info " + ss.string() + " --json");
        ASSERT_EQ(info.exitCode, 0);
        EXPECT_EQ(nlohmann::json::parse(info.out)["grids"].size(), 25u);
        for (int t : {0, 13, 24}) {
            ASSERT_EQ(runCli("decode " + ss.string() + " -o " + back.string() + " -f --grid mpld_asl_t" + std::to_string(t)).exitCode, 0) << t;
            expectSameScan(reference(series, t), reference(back), 1e-6, "mpld_asl grid " + std::to_string(t));
        }
    }
}

// The same MR as NIfTI (RAS) and as NRRD (LPS): the same samples and the
// same world transform once read.
TEST(ScanFormats, FlairNiftiEqualsFlairNrrd) {
    const fs::path nii = niftiDir() / "FLAIR.nii.gz", nrrd = denseDir() / "FLAIR.nrrd";
    if (!fs::exists(nii) || !fs::exists(nrrd) || !haveNibabel()) GTEST_SKIP() << "needs ../shared/data and python3-nibabel";
    const fs::path a = workDir() / "flair_nii.ssvdag", b = workDir() / "flair_nrrd.ssvdag";
    ASSERT_EQ(encode(nii, a).exitCode, 0);
    ASSERT_EQ(encode(nrrd, b).exitCode, 0);
    const fs::path aBack = workDir() / "flair_a.nrrd", bBack = workDir() / "flair_b.nrrd";
    ASSERT_EQ(runCli("decode " + a.string() + " -o " + aBack.string() + " -f").exitCode, 0);
    ASSERT_EQ(runCli("decode " + b.string() + " -o " + bBack.string() + " -f").exitCode, 0);
    expectSameScan(reference(aBack), reference(bBack), 1e-6, "FLAIR nii vs nrrd");
    expectSameScan(reference(nii), reference(nrrd), 1e-6, "FLAIR inputs (reference reader)");
    // `info` on either gives the header as read: the same extent, type, origin and axes.
    const Reference ref = reference(nii);
    for (const fs::path& scan : {nii, nrrd}) {
        const CommandResult info = runCli("info " + scan.string() + " --json");
        ASSERT_EQ(info.exitCode, 0) << info.err;
        const nlohmann::json h = nlohmann::json::parse(info.out);
        EXPECT_EQ(h["dims"], nlohmann::json(ref.dims)) << scan;
        EXPECT_EQ(h["sample_type"], "u8") << scan;
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(h["origin"][c].get<double>(), ref.lps[size_t(c)][3], 1e-4) << scan;
            for (int a = 0; a < 3; ++a) EXPECT_NEAR(h["axes"][a][c].get<double>(), ref.lps[size_t(c)][size_t(a)], 1e-6) << scan;
        }
    }
}

// Every shared dense scan, encoded once, comes back in every scan format
// with its samples byte for byte and its transform.
TEST(ScanFormats, EveryDenseScanComesBackInEveryFormat) {
    if (!fs::exists(denseDir()) || !haveNibabel()) GTEST_SKIP() << "needs ../shared/data/dense and python3-nibabel";
    int scans = 0;
    for (const auto& entry : fs::directory_iterator(denseDir())) {
        const fs::path in = entry.path();
        const std::string ext = in.extension().string();
        if (ext != ".nrrd" && ext != ".nhdr" && ext != ".mhd") continue;
        const Reference ref = reference(in);
        const fs::path ss = workDir() / "dense.ssvdag";
        ASSERT_EQ(encode(in, ss).exitCode, 0) << in;
        for (const std::string out : {"nrrd", "nhdr", "mha", "mhd", "nii", "nii.gz"}) {
            const fs::path back = workDir() / ("dense_back." + out);
            const CommandResult d = runCli("decode " + ss.string() + " -o " + back.string() + " -f");
            ASSERT_EQ(d.exitCode, 0) << in << " -> " << out << ": " << d.err;
            const bool nifti = out.rfind("nii", 0) == 0;
            expectSameScan(ref, reference(back), nifti ? 2e-5 : 1e-12, in.filename().string() + " -> " + out);
            fs::remove(back);
            fs::remove(workDir() / "dense_back.raw");
        }
        const fs::path raw = workDir() / "dense_back.raw";
        ASSERT_EQ(runCli("decode " + ss.string() + " -o " + raw.string() + " -f").exitCode, 0);
        EXPECT_TRUE(readAll(raw) == ref.samples) << in << " -> raw";
        ++scans;
    }
    EXPECT_GE(scans, 5);
}

// Rescaled, big-endian, paired, NIfTI-2 and 2-D files made by nibabel: the
// grid holds nibabel's scaled values (an int32 grid when slope and
// intercept are integers, a float grid otherwise), and decode to .nii.gz
// gives back the stored samples with the same slope and intercept.
TEST(ScanFormats, SyntheticNiftiFilesFromNibabel) {
    if (!haveNibabel()) GTEST_SKIP() << "needs python3-nibabel";
    const fs::path dir = workDir() / "synthetic";
    ASSERT_TRUE(runNibabel(dir, R"(rng = np.random.default_rng(7)
aff = np.array([[0.0, -1.2, 0.1, 30.0], [0.9, 0.0, 0.0, -12.5], [0.0, 0.05, 2.5, 7.0], [0, 0, 0, 1]])
def save(img, name, slope=None, inter=None):
    if slope is not None: img.header.set_slope_inter(slope, inter)
    nib.save(img, d + '/' + name)
    v = np.asanyarray(nib.load(d + '/' + name).get_fdata(dtype=np.float64))
    v.reshape(-1, order='F').astype('<f8').tofile(d + '/' + name + '.values')
ct = rng.integers(0, 3000, size=(17, 9, 6)).astype(np.int16)
save(nib.Nifti1Image(ct, aff), 'ct_hu.nii.gz', 1, -1024)
u = rng.integers(0, 65535, size=(8, 8, 8)).astype(np.uint16)
save(nib.Nifti1Image(u, aff), 'half.nii', 0.5, 10.25)
be = rng.integers(-30000, 30000, size=(5, 7, 3)).astype('>i2')
save(nib.Nifti1Image(be, aff), 'bigendian.nii')
f = rng.normal(size=(6, 5, 4)).astype(np.float32)
save(nib.Nifti2Image(f, aff), 'version2.nii')
p = rng.integers(0, 255, size=(9, 4, 5)).astype(np.uint8)
save(nib.Nifti1Pair(p, aff), 'pair.img')
flat = rng.integers(0, 255, size=(11, 13)).astype(np.uint8)
save(nib.Nifti1Image(flat, aff), 'flat.nii')
)"));
    struct Case {
        std::string file;
        bool intGrid;
    };
    for (const Case& c : {Case{"ct_hu.nii.gz", true}, Case{"half.nii", false}, Case{"bigendian.nii", true}, Case{"version2.nii", false},
                          Case{"pair.hdr", true}, Case{"flat.nii", true}}) {
        const fs::path in = dir / c.file;
        const fs::path ss = dir / (c.file + ".ssvdag"), vdb = dir / (c.file + ".vdb"), back = dir / (c.file + ".back.nii.gz");
        const CommandResult e = encode(in, ss);
        ASSERT_EQ(e.exitCode, 0) << c.file << ": " << e.err;
        ASSERT_EQ(runCli("decode " + ss.string() + " -o " + vdb.string() + " -f").exitCode, 0) << c.file;
        // The grid's values against nibabel's get_fdata, voxel by voxel.
        const std::string valuesFile = (dir / ((c.file == "pair.hdr" ? std::string("pair.img") : c.file) + ".values")).string();
        const std::string bytes = readAll(valuesFile);
        std::vector<double> expected(bytes.size() / 8);
        std::memcpy(expected.data(), bytes.data(), bytes.size());
        const Reference ref = reference(in);
        ASSERT_TRUE(ref.error.empty()) << c.file << ": " << ref.error;
        ASSERT_EQ(uint64_t(ref.dims[0] * ref.dims[1] * ref.dims[2]), expected.size()) << c.file;
        openvdb::initialize();
        openvdb::io::File file(vdb.string());
        file.open();
        openvdb::GridBase::Ptr base = file.readGrid(file.beginName().gridName());
        file.close();
        size_t checked = 0;
        auto check = [&](auto grid) {
            auto acc = grid->getConstAccessor();
            for (int64_t k = 0; k < ref.dims[2]; ++k)
                for (int64_t j = 0; j < ref.dims[1]; ++j)
                    for (int64_t i = 0; i < ref.dims[0]; ++i) {
                        const double want = expected[size_t((k * ref.dims[1] + j) * ref.dims[0] + i)];
                        const auto got = acc.getValue(openvdb::Coord(int(i), int(j), int(k)));
                        if constexpr (std::is_integral_v<decltype(got)>) ASSERT_EQ(double(got), want) << c.file << " at " << i << "," << j << "," << k;
                        else ASSERT_EQ(got, float(want)) << c.file << " at " << i << "," << j << "," << k;
                        ++checked;
                    }
        };
        if (c.intGrid) {
            auto g = openvdb::gridPtrCast<openvdb::Int32Grid>(base);
            ASSERT_TRUE(g) << c.file << " is " << base->type() << ", not an int32 grid";
            check(g);
        } else {
            auto g = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
            ASSERT_TRUE(g) << c.file << " is " << base->type() << ", not a float grid";
            check(g);
        }
        EXPECT_EQ(checked, expected.size());
        // Back as NIfTI: the stored samples, slope and intercept.
        const CommandResult d = runCli("decode " + ss.string() + " -o " + back.string() + " -f");
        ASSERT_EQ(d.exitCode, 0) << c.file << ": " << d.err;
        Reference got = reference(back);
        Reference want = ref;
        if (want.dtype == "i2" && c.file == "bigendian.nii") want.dtype = "i2";
        expectSameScan(want, got, 2e-5, c.file + " -> .nii.gz");
    }
}

// A level set (negative coordinates, inactive inside values, tiles) written
// as a scan: its bounding box, every voxel equal to OpenVDB's getValue.
TEST(ScanFormats, VdbGridAsScanEqualsOpenVdbValues) {
    openvdb::initialize();
    const fs::path dir = workDir() / "ls";
    fs::create_directories(dir);
    openvdb::FloatGrid::Ptr sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(9.0f, openvdb::Vec3f(-3, 2, 5), 0.5f, 3.0f);
    sphere->setName("sphere");
    const fs::path vdb = dir / "sphere.vdb", ss = dir / "sphere.ssvdag", out = dir / "sphere.raw";
    openvdb::io::File(vdb.string()).write({sphere});
    ASSERT_EQ(encode(vdb, ss).exitCode, 0);
    const CommandResult d = runCli("decode " + ss.string() + " -o " + out.string() + " -f");
    ASSERT_EQ(d.exitCode, 0) << d.err;
    // The extent: every active value and every stored value that is not
    // the background (the inside), voxels and tiles alike.
    openvdb::CoordBBox box;
    for (auto it = sphere->cbeginValueAll(); it; ++it)
        if (it.isValueOn() || *it != sphere->background()) box.expand(it.getBoundingBox());
    const openvdb::Coord lo = box.min(), size = box.dim();
    const std::string bytes = readAll(out);
    ASSERT_EQ(bytes.size(), size_t(size.x()) * size_t(size.y()) * size_t(size.z()) * 4u) << "extent " << size;
    std::vector<float> samples(bytes.size() / 4);
    std::memcpy(samples.data(), bytes.data(), bytes.size());
    auto acc = sphere->getConstAccessor();
    for (int k = 0; k < size.z(); ++k)
        for (int j = 0; j < size.y(); ++j)
            for (int i = 0; i < size.x(); ++i)
                ASSERT_EQ(samples[size_t((int64_t(k) * size.y() + j) * size.x() + i)], acc.getValue(lo + openvdb::Coord(i, j, k))) << i << "," << j << "," << k;
}

// Bad NIfTI input and impossible scan outputs: one line naming the file,
// exit 1, nothing written.
TEST(ScanFormats, BadNiftiAndImpossibleOutputsAreOneLine) {
    const fs::path dir = workDir() / "bad";
    fs::create_directories(dir);
    const fs::path ss = dir / "out.ssvdag";
    const fs::path garbage = dir / "garbage.nii";
    std::ofstream(garbage) << std::string(400, 'x');
    expectOneLineError(encode(garbage, ss), garbage.string(), "garbage");
    EXPECT_FALSE(fs::exists(ss));
    const fs::path flair = niftiDir() / "FLAIR.nii.gz";
    if (fs::exists(flair)) {
        const std::string whole = readAll(flair);
        const fs::path cut = dir / "cut.nii.gz";
        std::ofstream(cut, std::ios::binary) << whole.substr(0, whole.size() / 2);
        expectOneLineError(encode(cut, ss), cut.string(), "truncated");
        EXPECT_FALSE(fs::exists(ss));
        // The header claims 30000^3 samples: refused before anything is allocated.
        const CommandResult patched = runShell(kPython + " -c \"import nibabel as nib, numpy as np; i = nib.Nifti1Image(np.zeros((2,2,2), np.uint8), np.eye(4)); "
                                                         "nib.save(i, '" + (dir / "huge.nii").string() + "')\"");
        if (patched.exitCode == 0) {
            std::fstream f(dir / "huge.nii", std::ios::in | std::ios::out | std::ios::binary);
            const int16_t dims[4] = {3, 30000, 30000, 30000};
            f.seekp(40);
            f.write(reinterpret_cast<const char*>(dims), sizeof dims);
            f.close();
            expectOneLineError(encode(dir / "huge.nii", ss), (dir / "huge.nii").string(), "30000^3");
            EXPECT_FALSE(fs::exists(ss));
        }
    }
    // --normals is for a .vdb's level sets and vec3 grids: a scan is refused
    // (it was encoded without them, silently).
    const fs::path raw = dir / "tiny.raw", nhdr = dir / "tiny.nhdr";
    std::ofstream(raw, std::ios::binary) << std::string(8, '\x05');
    std::ofstream(nhdr) << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: tiny.raw\n";
    expectOneLineError(runCli("encode " + nhdr.string() + " -o " + ss.string() + " --normals 16"), "not to a dense scan", "normals of a scan");
    EXPECT_FALSE(fs::exists(ss));
    // An int64 grid has no scan sample type; two grids need --grid.
    openvdb::initialize();
    openvdb::Int64Grid::Ptr wide = openvdb::Int64Grid::create();
    wide->tree().setValue(openvdb::Coord(1, 2, 3), int64_t(1) << 40);
    wide->setName("wide");
    openvdb::FloatGrid::Ptr other = openvdb::FloatGrid::create();
    other->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    other->setName("other");
    const fs::path vdb = dir / "two.vdb", vss = dir / "two.ssvdag", out = dir / "two.nrrd";
    openvdb::io::File(vdb.string()).write({wide, other});
    ASSERT_EQ(encode(vdb, vss).exitCode, 0);
    expectOneLineError(runCli("decode " + vss.string() + " -o " + out.string()), "--grid NAME", "two grids to nrrd");
    expectOneLineError(runCli("decode " + vss.string() + " -o " + out.string() + " --grid wide"), "int64", "int64 grid to nrrd");
    EXPECT_FALSE(fs::exists(out));
    ASSERT_EQ(runCli("decode " + vss.string() + " -o " + out.string() + " --grid other").exitCode, 0);
}

// `--background-value V`: the removed samples come back as V, every other
// sample exactly; the report's PSNR figures match a closed-form MSE over
// the samples, with peak = the input range and = the 8-bit stored range.
TEST(ScanFormats, BackgroundValueComesBackAndPsnrStatesItsPeak) {
    const fs::path in = denseDir() / "cthead_256x256x99_uint8.nhdr";
    if (!fs::exists(in) || !haveNibabel()) GTEST_SKIP() << "needs ../shared/data/dense and python3-nibabel";
    const fs::path ss = workDir() / "bgv.ssvdag", back = workDir() / "bgv.nrrd";
    const CommandResult e = encode(in, ss, "--background-below 30 --background-value 7 --json");
    ASSERT_EQ(e.exitCode, 0) << e.err;
    const nlohmann::json report = nlohmann::json::parse(e.out)["threshold"];
    ASSERT_EQ(runCli("decode " + ss.string() + " -o " + back.string() + " -f").exitCode, 0);
    const Reference original = reference(in), got = reference(back);
    ASSERT_EQ(original.samples.size(), got.samples.size());
    double sumSq = 0, lo = 255, hi = 0;
    uint64_t removed = 0;
    for (size_t i = 0; i < original.samples.size(); ++i) {
        const int o = uint8_t(original.samples[i]), g = uint8_t(got.samples[i]);
        lo = std::min(lo, double(o));
        hi = std::max(hi, double(o));
        if (o < 30) {
            ++removed;
            ASSERT_EQ(g, 7) << "sample " << i;
            sumSq += double(o - 7) * double(o - 7);
        } else {
            ASSERT_EQ(g, o) << "sample " << i;
        }
    }
    const double mse = sumSq / double(original.samples.size());
    EXPECT_EQ(report["inactive_samples"].get<uint64_t>(), removed);
    EXPECT_EQ(report["background_value"].get<double>(), 7.0);
    EXPECT_EQ(report["background_is"], "chosen");
    EXPECT_NEAR(report["psnr_db"].get<double>(), 10 * std::log10((hi - lo) * (hi - lo) / mse), 1e-9);
    EXPECT_EQ(report["stored_bits"].get<unsigned>(), 8u);
    EXPECT_NEAR(report["psnr_stored_range_db"].get<double>(), 10 * std::log10(255.0 * 255.0 / mse), 1e-9);
    // `info` shows where the grid came from and what the threshold cost.
    const CommandResult info = runCli("info " + ss.string() + " --json");
    ASSERT_EQ(info.exitCode, 0) << info.err;
    const nlohmann::json scan = nlohmann::json::parse(info.out)["grids"][0]["scan"];
    EXPECT_EQ(scan["sample_type"], "u8");
    EXPECT_EQ(scan["dims"], nlohmann::json({256, 256, 99}));
    EXPECT_EQ(scan["background_below"].get<double>(), 30.0);
    EXPECT_EQ(scan["threshold"]["inactive_samples"].get<uint64_t>(), removed);
    EXPECT_NEAR(scan["threshold"]["psnr_db"].get<double>(), 10 * std::log10((hi - lo) * (hi - lo) / mse), 1e-9);
    EXPECT_NE(runCli("info " + ss.string()).out.find("threshold (below 30): " + std::to_string(removed) + " samples inactive"), std::string::npos);
    expectOneLineError(encode(in, ss, "--background-value 7"), "needs --background-below", "value without threshold");
    expectOneLineError(encode(in, ss, "--background-below 30 --background-value 7.5"), "not a value of this integer grid", "fractional");
}

// RGB24 and vector (5th dimension of 3) NIfTI made by nibabel become a
// Vec3I grid named Cd and a Vec3S grid, bit-exact against OpenVDB's
// accessor; each comes back as NIfTI, 4-D NRRD and 3-channel MetaImage, and
// those read back give the same samples again.
TEST(ScanFormats, ColourAndVectorScansRoundTrip) {
    if (!haveNibabel()) GTEST_SKIP() << "needs python3-nibabel";
    const fs::path dir = workDir() / "vectors";
    ASSERT_TRUE(runNibabel(dir, R"(rng = np.random.default_rng(11)
aff = np.array([[1.5, 0.0, 0.0, -4.0], [0.0, 0.75, 0.0, 2.0], [0.0, 0.0, 2.0, 9.0], [0, 0, 0, 1]])
a = rng.integers(0, 256, size=(7, 6, 5, 3)).astype(np.uint8)
rgb = np.zeros((7, 6, 5), dtype=[('R', 'u1'), ('G', 'u1'), ('B', 'u1')])
rgb['R'], rgb['G'], rgb['B'] = a[..., 0], a[..., 1], a[..., 2]
nib.save(nib.Nifti1Image(rgb, aff), d + '/rgb.nii.gz')
vec = rng.normal(size=(6, 4, 5, 1, 3)).astype(np.float32)
img = nib.Nifti1Image(vec, aff)
img.header.set_intent('vector')
nib.save(img, d + '/vec.nii.gz')
)"));
    openvdb::initialize();
    for (const std::string name : {"rgb", "vec"}) {
        const fs::path in = dir / (name + ".nii.gz"), ss = dir / (name + ".ssvdag"), vdb = dir / (name + ".vdb");
        const Reference ref = reference(in);
        ASSERT_TRUE(ref.error.empty()) << ref.error;
        const CommandResult e = encode(in, ss);
        ASSERT_EQ(e.exitCode, 0) << name << ": " << e.err;
        ASSERT_EQ(runCli("decode " + ss.string() + " -o " + vdb.string() + " -f").exitCode, 0);
        openvdb::io::File file(vdb.string());
        file.open();
        openvdb::GridBase::Ptr base = file.readGrid(file.beginName().gridName());
        file.close();
        const size_t voxels = size_t(ref.dims[0] * ref.dims[1] * ref.dims[2]);
        auto check = [&](auto grid, auto component) {
            using C = decltype(component);
            ASSERT_EQ(ref.samples.size(), voxels * 3 * sizeof(C) / (name == std::string("rgb") ? sizeof(C) : 1));
            auto acc = grid->getConstAccessor();
            for (int64_t k = 0; k < ref.dims[2]; ++k)
                for (int64_t j = 0; j < ref.dims[1]; ++j)
                    for (int64_t i = 0; i < ref.dims[0]; ++i) {
                        const size_t at = size_t((k * ref.dims[1] + j) * ref.dims[0] + i) * 3;
                        const auto v = acc.getValue(openvdb::Coord(int(i), int(j), int(k)));
                        for (int c = 0; c < 3; ++c) {
                            C want;
                            if constexpr (std::is_same_v<C, float>) std::memcpy(&want, ref.samples.data() + (at + size_t(c)) * 4, 4);
                            else want = C(uint8_t(ref.samples[at + size_t(c)]));
                            ASSERT_EQ(v[c], want) << name << " at " << i << "," << j << "," << k << " component " << c;
                        }
                    }
        };
        if (name == "rgb") {
            EXPECT_EQ(base->getName(), "Cd");
            auto g = openvdb::gridPtrCast<openvdb::Vec3IGrid>(base);
            ASSERT_TRUE(g) << base->type();
            check(g, int32_t{});
        } else {
            auto g = openvdb::gridPtrCast<openvdb::Vec3SGrid>(base);
            ASSERT_TRUE(g) << base->type();
            check(g, float{});
        }
        for (const std::string out : {"nii.gz", "nrrd", "mha"}) {
            const fs::path back = dir / (name + "_back." + out), ss2 = dir / (name + "_again.ssvdag"), again = dir / (name + "_again.nii.gz");
            ASSERT_EQ(runCli("decode " + ss.string() + " -o " + back.string() + " -f").exitCode, 0) << name << " -> " << out;
            expectSameScan(ref, reference(back), 2e-6, name + " -> " + out);
            // ... and read back by vdbdag itself.
            ASSERT_EQ(encode(back, ss2).exitCode, 0) << name << " " << out;
            ASSERT_EQ(runCli("decode " + ss2.string() + " -o " + again.string() + " -f").exitCode, 0);
            expectSameScan(ref, reference(again), 2e-6, name + " -> " + out + " -> nii.gz");
        }
    }
}

// `diff SCAN THRESHOLDED.ssvdag` counts the samples the threshold made
// inactive and, over all the scan's samples, gives encode's own figures.
TEST(ScanFormats, DiffOfAThresholdedScanEqualsTheEncodeReport) {
    const fs::path in = denseDir() / "cthead_256x256x99_uint8.nhdr";
    if (!fs::exists(in)) GTEST_SKIP() << "needs ../shared/data/dense";
    const fs::path ss = workDir() / "diff_th.ssvdag";
    const CommandResult e = encode(in, ss, "--background-below 40 --json");
    ASSERT_EQ(e.exitCode, 0) << e.err;
    const nlohmann::json th = nlohmann::json::parse(e.out)["threshold"];
    const CommandResult d = runCli("diff " + in.string() + " " + ss.string() + " --json");
    EXPECT_EQ(d.exitCode, 1) << d.err;  // they differ
    const nlohmann::json g = nlohmann::json::parse(d.out)["grids"][0];
    EXPECT_EQ(g["voxels"]["only_in_a"].get<uint64_t>(), th["inactive_samples"].get<uint64_t>());
    EXPECT_EQ(g["voxels"]["only_in_b"].get<uint64_t>(), 0u);
    EXPECT_EQ(g["voxels"]["value_differs"].get<uint64_t>(), 0u);
    const nlohmann::json all = g["over_all_of_a"];
    EXPECT_EQ(all["voxels"].get<uint64_t>(), th["samples"].get<uint64_t>());
    EXPECT_DOUBLE_EQ(all["max_abs_error"].get<double>(), th["max_abs_change"].get<double>());
    EXPECT_NEAR(all["mean_abs_error"].get<double>(), th["mean_abs_change"].get<double>(), 1e-9);
    EXPECT_NEAR(all["rms_error"].get<double>(), th["rms_change"].get<double>(), 1e-9);
    EXPECT_NEAR(all["psnr_db"].get<double>(), th["psnr_db"].get<double>(), 1e-9);
}

// RGBA32 NIfTI made by nibabel becomes a Vec3I colour grid "Cd" and an Int32
// grid "alpha", every sample exact against numpy's array (read through
// OpenVDB's accessor); `decode --grid alpha -o .nii.gz` gives the alpha
// plane back as a u8 volume nibabel reads as the same samples.
TEST(ScanFormats, RgbaNiftiIsAColourAndAnAlphaGrid) {
    if (!haveNibabel()) GTEST_SKIP() << "needs python3-nibabel";
    const fs::path dir = workDir() / "rgba";
    ASSERT_TRUE(runNibabel(dir, R"(rng = np.random.default_rng(12)
a = rng.integers(0, 256, size=(5, 7, 4, 4)).astype(np.uint8)
rgba = np.zeros((5, 7, 4), dtype=[('R', 'u1'), ('G', 'u1'), ('B', 'u1'), ('A', 'u1')])
for i, c in enumerate('RGBA'): rgba[c] = a[..., i]
nib.save(nib.Nifti1Image(rgba, np.diag([2.0, 1.0, 0.5, 1.0])), d + '/rgba.nii.gz')
np.ascontiguousarray(np.transpose(a, (2, 1, 0, 3))).tofile(d + '/rgba.expected')
np.ascontiguousarray(np.transpose(a[..., 3], (2, 1, 0))).tofile(d + '/alpha.expected')
)"));
    const std::string expected = readAll(dir / "rgba.expected");
    ASSERT_EQ(expected.size(), size_t(5 * 7 * 4 * 4));
    const fs::path in = dir / "rgba.nii.gz", ss = dir / "rgba.ssvdag", vdb = dir / "rgba.vdb";
    ASSERT_EQ(encode(in, ss).exitCode, 0);
    ASSERT_EQ(runCli("decode " + ss.string() + " -o " + vdb.string() + " -f").exitCode, 0);
    openvdb::initialize();
    openvdb::io::File file(vdb.string());
    file.open();
    auto cd = openvdb::gridPtrCast<openvdb::Vec3IGrid>(file.readGrid("Cd"));
    auto alpha = openvdb::gridPtrCast<openvdb::Int32Grid>(file.readGrid("alpha"));
    file.close();
    ASSERT_TRUE(cd && alpha);
    EXPECT_EQ(cd->activeVoxelCount(), 5u * 7u * 4u);
    EXPECT_EQ(alpha->activeVoxelCount(), 5u * 7u * 4u);
    auto c = cd->getConstAccessor();
    auto al = alpha->getConstAccessor();
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 7; ++j)
            for (int i = 0; i < 5; ++i) {
                const size_t at = size_t((k * 7 + j) * 5 + i) * 4;
                const openvdb::Coord ijk(i, j, k);
                for (int ch = 0; ch < 3; ++ch) ASSERT_EQ(c.getValue(ijk)[ch], int(uint8_t(expected[at + size_t(ch)]))) << i << "," << j << "," << k;
                ASSERT_EQ(al.getValue(ijk), int(uint8_t(expected[at + 3]))) << i << "," << j << "," << k;
            }
    const fs::path back = dir / "alpha_back.nii.gz";
    ASSERT_EQ(runCli("decode " + ss.string() + " --grid alpha -o " + back.string() + " -f").exitCode, 0);
    const Reference ref = reference(back);
    ASSERT_TRUE(ref.error.empty()) << ref.error;
    EXPECT_EQ(ref.dtype, "u1");
    EXPECT_TRUE(ref.samples == readAll(dir / "alpha.expected"));
}

// A .raw volume whose name gives its layout is a scan like the others:
// `info` describes it from the name (dims and type, a closed form here), and
// a command that reads .ssvdag files only (decode) names it as a raw volume
// and says which command takes it, rather than "bad magic" (issue 38 #10).
TEST(ScanFormats, ARawVolumeIsDescribedByItsNameAndNamedWhereItIsNotRead) {
    const fs::path raw = workDir() / "ct_6x5x4_int16le.raw";
    std::ofstream(raw, std::ios::binary) << std::string(6 * 5 * 4 * 2, '\1');
    const CommandResult info = runCli("info " + raw.string() + " --json");
    ASSERT_EQ(info.exitCode, 0) << info.err;
    const nlohmann::json h = nlohmann::json::parse(info.out);
    EXPECT_EQ(h["dims"], nlohmann::json({6, 5, 4})) << info.out;
    EXPECT_EQ(h["sample_type"], "i16") << info.out;
    const fs::path vdb = workDir() / "raw_decoded.vdb";
    fs::remove(vdb);
    const CommandResult decode = runCli("decode " + raw.string() + " -o " + vdb.string());
    EXPECT_EQ(decode.exitCode, 1);
    EXPECT_EQ(std::count(decode.err.begin(), decode.err.end(), '\n'), 1) << decode.err;
    EXPECT_NE(decode.err.find("it is a raw volume"), std::string::npos) << decode.err;
    EXPECT_NE(decode.err.find("vdbdag encode " + raw.string()), std::string::npos) << decode.err;
    EXPECT_FALSE(fs::exists(vdb));
}
