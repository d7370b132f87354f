// DICOM input (vdb_bridge/DicomSeries.h): the shared series come back
// sample for sample and with the same geometry as pydicom gives them
// (tests/tools/dicom_reference.py stacks the files by ImagePositionPatient .
// normal, never with vdbdag code); series are listed and picked, mixes are
// refused in one line, slices are ordered by position rather than by name,
// rescales are applied, non-image objects, duplicates, gaps, truncated files
// and non-DICOM folders give one-line errors naming the file. Skipped when
// ../shared/data or python3 with pydicom is missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "tests/unit/BuildPaths.h"
#include "src/util/Error.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/DicomSeries.h"

namespace fs = std::filesystem;
using namespace vdbdag;
using namespace vdbdag::bridge;
using vdbdag::testing::runCli;
using vdbdag::testing::runShell;

namespace {

const fs::path kDicom = fs::path(VDBDAG_SHARED_DATA) / "medical" / "dicom";
const fs::path kAdi = kDicom / "adi_brain";
const fs::path kPet = kDicom / "rsna_2" / "PET";
const fs::path kSeg = kDicom / "rsna_2" / "SEG";
const std::string kPetUid = "1.3.6.1.4.1.14519.5.2.1.2744.7002.117357550898198415937979788256";
const std::string kT1Uid = "1.3.12.2.1107.5.2.32.35235.2012041417312491079284166.0.0.0";     // 175 slices 192x192, one missing
const std::string kT2Uid = "1.3.12.2.1107.5.2.32.35235.2012041417405580603808736.0.0.0";     // 55 slices 384x512, one missing
const std::string kPerfUid = "1.3.12.2.1107.5.2.32.35235.2012041417554381589324478.0.0.0";   // one slice
const std::string kRelCbfUid = "1.3.12.2.1107.5.2.32.35235.2012041417554381589424479.0.0.0"; // one slice

fs::path scriptPath() { return fs::path(__FILE__).parent_path().parent_path() / "tools" / "dicom_reference.py"; }

// A python with pydicom and numpy ("" when there is none): the PATH's
// python3 may be another installation than Debian's.
const std::string& python() {
    static const std::string found = [] {
        for (const char* candidate : {"python3", "/usr/bin/python3"})
            if (runShell(std::string(candidate) + " -c 'import pydicom, numpy' >/dev/null").exitCode == 0) return std::string(candidate);
        return std::string();
    }();
    return found;
}

#define REQUIRE_REFERENCE()                                                                                   \
    do {                                                                                                      \
        if (!fs::is_directory(kAdi) || !fs::is_directory(kPet)) GTEST_SKIP() << "../shared/data/medical absent"; \
        if (python().empty()) GTEST_SKIP() << "python3 with pydicom not available";                             \
    } while (0)

fs::path workDir() {
    struct Dir {
        fs::path path = fs::temp_directory_path() / ("vdbdag_dicom_" + std::to_string(getpid()));
        Dir() {
            fs::remove_all(path);  // a finished process with the same PID may have left it
            fs::create_directories(path);
        }
        ~Dir() {
            std::error_code ec;
            fs::remove_all(path, ec);
        }
    };
    static const Dir dir;
    return dir.path;
}

fs::path freshDir(const std::string& name) {
    const fs::path d = workDir() / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string quote(const fs::path& p) { return "'" + p.string() + "'"; }

std::vector<uint8_t> readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

struct Reference {
    nlohmann::json meta;
    std::vector<uint8_t> raw;
};

// pydicom's stack of series `uid` in `folder`.
Reference reference(const fs::path& folder, const std::string& uid) {
    static int counter = 0;
    const fs::path out = workDir() / ("ref" + std::to_string(counter++));
    const auto r = runShell(python() + " " + quote(scriptPath()) + " stack " + quote(folder) + " " + uid + " " + quote(out));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    Reference ref;
    std::ifstream in(out.string() + ".json");
    ref.meta = nlohmann::json::parse(in);
    ref.raw = readAll(out.string() + ".raw");
    return ref;
}

std::vector<uint8_t> readSamples(const DenseVolume& v) {
    std::vector<uint8_t> all, part;
    const std::unique_ptr<SliceReader> reader = openDicomSlices(v);
    for (int64_t z = 0; z < v.dims[2]; z += 7) {  // an odd slab size on purpose
        reader->readSlices(std::min<int64_t>(7, v.dims[2] - z), part);
        all.insert(all.end(), part.begin(), part.end());
    }
    return all;
}

void expectGeometry(const DenseVolume& v, const nlohmann::json& m) {
    for (int a = 0; a < 3; ++a) EXPECT_EQ(v.dims[size_t(a)], m["dims"][a].get<int64_t>()) << "axis " << a;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(v.origin[size_t(c)], m["origin"][c].get<double>(), 1e-6);
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(v.axes[size_t(a)][size_t(c)], m["axes"][a][c].get<double>(), 1e-6) << "axis " << a << " component " << c;
    EXPECT_EQ(v.rescaleSlope, m["slope"].get<double>());
    EXPECT_EQ(v.rescaleIntercept, m["intercept"].get<double>());
    EXPECT_EQ(v.space, "LPS");
}

// The grid's transform (world = [i j k 1] * M) against pydicom's origin and axes.
void expectTransform(const GridRecord& g, const nlohmann::json& m) {
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(g.indexToWorld[size_t(a * 4 + c)], m["axes"][a][c].get<double>(), 1e-6);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(g.indexToWorld[size_t(12 + c)], m["origin"][c].get<double>(), 1e-6);
}

// Calls fn(x, y, z, value) for every active voxel of a dense import (T its value type).
template <typename T, typename F>
void forEachVoxel(const GridRecord& g, F fn) {
    // Each voxel of a brick, then of a tile (a scan's solid 8^3 blocks), with its value.
    const T* values = reinterpret_cast<const T*>(g.values.bricks.data());
    uint64_t index = 0;
    for (const auto& b : g.topology.bricks)
        for (int bit = 0; bit < 64; ++bit)
            if (b.mask >> bit & 1) fn(int64_t(b.x + (bit & 3)), int64_t(b.y + ((bit >> 2) & 3)), int64_t(b.z + (bit >> 4)), values[index++]);
    const T* tileValues = reinterpret_cast<const T*>(g.values.tiles.data());
    for (size_t t = 0; t < g.topology.tiles.size(); ++t) {
        const auto& tile = g.topology.tiles[t];
        const int64_t n = int64_t(1) << tile.log2Size;
        for (int64_t z = 0; z < n; ++z)
            for (int64_t y = 0; y < n; ++y)
                for (int64_t x = 0; x < n; ++x) fn(tile.x + x, tile.y + y, tile.z + z, tileValues[t]);
    }
}

bool oneLine(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

std::string errorOf(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

// Copies `files` into `dir` under new names (reversed order: the last file
// first), so names say nothing of positions.
void copyRenamed(const std::vector<std::string>& files, const fs::path& dir, unsigned seed) {
    std::vector<size_t> names(files.size());
    for (size_t i = 0; i < names.size(); ++i) names[i] = files.size() - i;
    std::mt19937 rng(seed);
    std::shuffle(names.begin(), names.end(), rng);
    for (size_t i = 0; i < files.size(); ++i) fs::copy_file(files[i], dir / ("IM" + std::to_string(1000 + names[i])));
}

// The PET files in slice order (pydicom's): their names say nothing of it.
const std::vector<std::string>& petByPosition() {
    static const std::vector<std::string> files = [] {
        std::vector<std::string> out;
        const Reference ref = reference(kPet, kPetUid);
        for (const auto& f : ref.meta["files"]) out.push_back(f.get<std::string>());
        return out;
    }();
    return files;
}

DenseImportOptions quietOptions(const std::string& series = "") {
    DenseImportOptions o;
    o.showProgress = false;
    o.series = series;
    return o;
}

} // namespace

TEST(DicomScan, AdiBrainListsItsSeriesLikePydicom) {
    REQUIRE_REFERENCE();
    const auto r = runShell(python() + " " + quote(scriptPath()) + " list " + quote(kAdi));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json ref = nlohmann::json::parse(r.out);
    const DicomScan scan = scanDicom(kAdi.string());
    ASSERT_EQ(scan.series.size(), ref["series"].size());
    // Listing order: series number (5, 6, 17, 18).
    const std::vector<std::string> uids{kT1Uid, kT2Uid, kPerfUid, kRelCbfUid};
    for (size_t i = 0; i < uids.size(); ++i) {
        const DicomSeriesInfo& s = scan.series[i];
        EXPECT_EQ(s.uid, uids[i]);
        EXPECT_EQ(s.modality, "MR");
        // The two stacks each miss one slice (instances 115 and 35): one empty slot each.
        EXPECT_EQ(s.dims[2], ref["series"][s.uid].get<int64_t>() + (i < 2 ? 1 : 0)) << s.uid;
        EXPECT_EQ(s.sampleType, "u16");
    }
    EXPECT_EQ(scan.series[0].dims, (std::array<int64_t, 3>{192, 192, 176}));
    EXPECT_EQ(scan.series[1].dims, (std::array<int64_t, 3>{384, 512, 56}));
    EXPECT_EQ(scan.series[2].dims, (std::array<int64_t, 3>{256, 256, 1}));
    EXPECT_EQ(scan.series[1].description, "AX FSE T2");
    EXPECT_NEAR(scan.series[1].spacing[0], 0.4296875, 1e-6);
    EXPECT_NEAR(scan.series[1].spacing[2], 2.5, 1e-6);
    // Both stacks miss one slice: they convert, with a note; so do the single slices.
    for (int i = 0; i < 2; ++i) {
        EXPECT_TRUE(scan.series[size_t(i)].problem.empty()) << scan.series[size_t(i)].problem;
        ASSERT_FALSE(scan.series[size_t(i)].notes.empty());
        EXPECT_NE(scan.series[size_t(i)].notes.back().find("1 missing slice"), std::string::npos) << scan.series[size_t(i)].notes.back();
    }
    EXPECT_TRUE(scan.series[2].problem.empty()) << scan.series[2].problem;
    EXPECT_TRUE(scan.series[3].problem.empty()) << scan.series[3].problem;
    // The files that are not DICOM, each with its reason.
    ASSERT_EQ(scan.skipped.size(), ref["non_dicom"].size());
    for (const auto& f : ref["non_dicom"]) {
        const std::string name = f.get<std::string>();
        EXPECT_TRUE(std::any_of(scan.skipped.begin(), scan.skipped.end(), [&](const std::string& s) { return s.rfind(name + ": not a DICOM file", 0) == 0; }))
            << name;
    }
}

// A stack missing slices keeps the regular step: each missing slice is an
// empty slot of inactive voxels, named in a note, and every other slice
// equals pydicom's at the slot its position gives (independently: the
// position over the median step).
TEST(DicomSeries, MissingSlicesAreEmptySlotsAtTheRegularStep) {
    REQUIRE_REFERENCE();
    for (const auto& [uid, after] : {std::pair{kT2Uid, std::string("36444406")}, std::pair{kT1Uid, std::string("36749446")}}) {
        SCOPED_TRACE(uid);
        const Reference ref = reference(kAdi, uid);
        std::vector<double> pos;
        for (const auto& p : ref.meta["positions"]) pos.push_back(p.get<double>());
        std::vector<double> steps;
        for (size_t i = 1; i < pos.size(); ++i) steps.push_back(pos[i] - pos[i - 1]);
        std::nth_element(steps.begin(), steps.begin() + ptrdiff_t(steps.size() / 2), steps.end());
        const double step = steps[steps.size() / 2];
        std::vector<int64_t> slotOf;
        for (double p : pos) slotOf.push_back(std::llround((p - pos[0]) / step));
        std::vector<int64_t> missing;
        for (int64_t z = 0, i = 0; z <= slotOf.back(); ++z) {
            if (i < int64_t(slotOf.size()) && slotOf[size_t(i)] == z) ++i;
            else missing.push_back(z);
        }
        ASSERT_EQ(missing.size(), 1u);
        const DenseVolume v = describeDicomSeries(kAdi.string(), uid);
        EXPECT_EQ(v.dims[2], slotOf.back() + 1);
        EXPECT_EQ(v.missingSlices, missing);
        ASSERT_FALSE(v.notes.empty());
        EXPECT_NE(v.notes.back().find("1 missing slice"), std::string::npos) << v.notes.back();
        EXPECT_NE(v.notes.back().find((kAdi / after).string()), std::string::npos) << v.notes.back();
        const int64_t n = int64_t(pos.size());
        for (int c = 0; c < 3; ++c)  // pydicom's step over the present slices, spread over the slots
            EXPECT_NEAR(v.axes[2][size_t(c)], ref.meta["axes"][2][c].get<double>() * double(n - 1) / double(v.dims[2] - 1), 1e-6);
        const DenseImportResult imported = importDense(kAdi.string(), quietOptions(uid));
        const GridRecord& g = imported.volume.grids.front();
        ASSERT_EQ(g.valueType, ValueType::Int32);
        const auto* stored = reinterpret_cast<const uint16_t*>(ref.raw.data());
        std::vector<int64_t> sliceOfSlot(size_t(v.dims[2]), -1);
        for (size_t i = 0; i < slotOf.size(); ++i) sliceOfSlot[size_t(slotOf[i])] = int64_t(i);
        uint64_t count = 0, wrong = 0;
        forEachVoxel<int32_t>(g, [&](int64_t x, int64_t y, int64_t z, int32_t value) {
            const int64_t slice = sliceOfSlot[size_t(z)];
            if (slice < 0) { ++wrong; return; }  // a voxel in the missing slot
            if (value != int32_t(stored[(slice * v.dims[1] + y) * v.dims[0] + x])) ++wrong;
            ++count;
        });
        EXPECT_EQ(wrong, 0u);
        EXPECT_EQ(count, uint64_t(n) * v.sliceSamples());
    }
}

TEST(DicomSeries, SingleSliceSeriesMatchPydicom) {
    REQUIRE_REFERENCE();
    for (const std::string& uid : {kPerfUid, kRelCbfUid}) {
        SCOPED_TRACE(uid);
        const Reference ref = reference(kAdi, uid);
        const DenseVolume v = describeDicomSeries(kAdi.string(), uid);
        EXPECT_EQ(v.format, DenseFormat::Dicom);
        EXPECT_EQ(v.type, SampleType::U16);
        ASSERT_EQ(ref.meta["dtype"], "uint16");
        expectGeometry(v, ref.meta);
        EXPECT_EQ(readSamples(v), ref.raw);
        // importDense: slope 2.000244140625 -> a float grid of stored * slope + intercept.
        const DenseImportResult imported = importDense(kAdi.string(), quietOptions(uid));
        ASSERT_EQ(imported.volume.grids.size(), 1u);
        const GridRecord& g = imported.volume.grids.front();
        expectTransform(g, ref.meta);
        ASSERT_EQ(g.valueType, ValueType::Float);
        const auto* stored = reinterpret_cast<const uint16_t*>(ref.raw.data());
        uint64_t count = 0;
        forEachVoxel<float>(g, [&](int64_t x, int64_t y, int64_t z, float value) {
            const double expect = double(stored[(z * v.dims[1] + y) * v.dims[0] + x]) * ref.meta["slope"].get<double>() + ref.meta["intercept"].get<double>();
            if (value != float(expect) && count < 5) ADD_FAILURE() << "voxel " << x << "," << y << "," << z << ": " << value << " vs " << expect;
            ++count;
        });
        EXPECT_EQ(count, v.sampleCount());
    }
}

TEST(DicomSeries, ContiguousPartsOfTheMrStacksMatchPydicom) {
    REQUIRE_REFERENCE();
    for (const std::string& uid : {kT2Uid, kT1Uid}) {
        SCOPED_TRACE(uid);
        // The slices below the gap (found from pydicom's positions), copied
        // under shuffled names.
        const Reference whole = reference(kAdi, uid);
        const auto& pos = whole.meta["positions"];
        size_t gap = 0;
        for (size_t i = 0; i + 1 < pos.size(); ++i)
            if (pos[i + 1].get<double>() - pos[i].get<double>() > pos[gap + 1].get<double>() - pos[gap].get<double>()) gap = i;
        std::vector<std::string> files;
        for (size_t i = 0; i <= gap; ++i) files.push_back(whole.meta["files"][i].get<std::string>());
        ASSERT_GE(files.size(), 30u);
        const fs::path dir = freshDir("part_" + uid.substr(uid.size() - 12));
        copyRenamed(files, dir, 7);
        const Reference ref = reference(dir, uid);
        const DenseVolume v = describeDicomSeries(dir.string(), "");
        expectGeometry(v, ref.meta);
        EXPECT_EQ(v.dims[2], int64_t(files.size()));
        EXPECT_EQ(readSamples(v), ref.raw);
        const DenseImportResult imported = importDense(dir.string(), quietOptions());
        expectTransform(imported.volume.grids.front(), ref.meta);
        EXPECT_EQ(imported.volume.grids.front().valueType, ValueType::Int32);
    }
}

TEST(DicomSeries, AFolderOfSeveralSeriesNeedsAChoice) {
    REQUIRE_REFERENCE();
    const std::string e = errorOf([] { describeDicomSeries(kAdi.string(), ""); });
    ASSERT_TRUE(oneLine(e)) << e;
    EXPECT_EQ(e.rfind(kAdi.string() + ": holds 4 series, pick one with --series N or UID: 1) " + kT1Uid + " MR \"mocoMEMPRAGE_220FOV RMS\" 192x192x176", 0),
              0u)
        << e;
    for (const std::string& uid : {kT1Uid, kT2Uid, kPerfUid, kRelCbfUid}) EXPECT_NE(e.find(uid), std::string::npos) << uid;
    EXPECT_NE(e.find("4) " + kRelCbfUid), std::string::npos);
    // By number and by UID: the same series.
    EXPECT_EQ(describeDicomSeries(kAdi.string(), "3").slices.front().file, describeDicomSeries(kAdi.string(), kPerfUid).slices.front().file);
    for (const char* bad : {"0", "5", "99999999999999999999", "1.2.3"}) {
        const std::string m = errorOf([&] { describeDicomSeries(kAdi.string(), bad); });
        EXPECT_TRUE(oneLine(m)) << bad << ": " << m;
        EXPECT_EQ(m.rfind(kAdi.string() + ": ", 0), 0u) << m;
    }
}

TEST(DicomSeries, PetConvertsWithItsRescale) {
    REQUIRE_REFERENCE();
    const Reference ref = reference(kPet, kPetUid);
    const DenseVolume v = describeDicomSeries(kPet.string(), "");
    EXPECT_EQ(v.type, SampleType::I16);
    ASSERT_EQ(ref.meta["dtype"], "int16");
    expectGeometry(v, ref.meta);
    EXPECT_EQ(v.rescaleSlope, 2.0222414);
    EXPECT_EQ(v.rescaleIntercept, 0.0);
    EXPECT_EQ(readSamples(v), ref.raw);
    const DenseImportResult imported = importDense(kPet.string(), quietOptions());
    const GridRecord& g = imported.volume.grids.front();
    expectTransform(g, ref.meta);
    ASSERT_EQ(g.valueType, ValueType::Float);
    const auto* stored = reinterpret_cast<const int16_t*>(ref.raw.data());
    const double slope = ref.meta["slope"], intercept = ref.meta["intercept"];
    uint64_t count = 0, wrong = 0, nonzero = 0;
    forEachVoxel<float>(g, [&](int64_t x, int64_t y, int64_t z, float value) {
        const int16_t s = stored[(z * 128 + y) * 128 + x];
        if (value != float(double(s) * slope + intercept)) ++wrong;
        if (s != 0) ++nonzero;
        ++count;
    });
    EXPECT_EQ(count, v.sampleCount());
    EXPECT_EQ(wrong, 0u);
    EXPECT_GT(nonzero, count / 10);
}

TEST(DicomSeries, OrderIsByPositionNotByName) {
    REQUIRE_REFERENCE();
    const DenseVolume original = describeDicomSeries(kPet.string(), "");
    const std::vector<uint8_t> samples = readSamples(original);
    std::vector<std::string> files;
    for (const auto& e : fs::directory_iterator(kPet)) files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    const fs::path dir = freshDir("shuffled");
    fs::create_directories(dir / "sub");
    copyRenamed(std::vector<std::string>(files.begin(), files.begin() + 150), dir, 1);
    copyRenamed(std::vector<std::string>(files.begin() + 150, files.end()), dir / "sub", 2);  // and in a subfolder
    const DenseVolume v = describeDicomSeries(dir.string(), "");
    EXPECT_EQ(v.dims, original.dims);
    EXPECT_EQ(v.origin, original.origin);
    EXPECT_EQ(v.axes, original.axes);
    EXPECT_EQ(readSamples(v), samples);
}

TEST(DicomSeries, MultiFrameFilesGiveTheSameSamples) {
    REQUIRE_REFERENCE();
    const DenseVolume original = describeDicomSeries(kPet.string(), "");
    const std::vector<uint8_t> samples = readSamples(original);
    for (const char* mode : {"perframe", "spacing"}) {
        SCOPED_TRACE(mode);
        const fs::path dir = freshDir(std::string("multiframe_") + mode);
        const fs::path file = dir / "frames.dcm";
        const auto r = runShell(python() + " " + quote(scriptPath()) + " multiframe " + quote(kPet) + " " + kPetUid + " " + quote(file) + " " + mode);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const DenseVolume v = describeDicomSeries(file.string(), "");
        EXPECT_EQ(v.dims, original.dims);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(v.origin[size_t(c)], original.origin[size_t(c)], 1e-6);
        for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(v.axes[size_t(a)][size_t(c)], original.axes[size_t(a)][size_t(c)], 1e-6);
        EXPECT_EQ(v.rescaleSlope, original.rescaleSlope);
        EXPECT_EQ(readSamples(v), samples);
        // The same frames in RLE, one fragment per frame (each checked
        // before GDCM decodes it: detail/DicomRle.h).
        if (runShell("gdcmconv --version >/dev/null").exitCode != 0) continue;
        const fs::path rle = dir / "frames_rle.dcm";
        const auto c = runShell("gdcmconv --rle " + quote(file) + " " + quote(rle));
        ASSERT_EQ(c.exitCode, 0) << c.err;
        EXPECT_EQ(readSamples(describeDicomSeries(rle.string(), "")), samples);
    }
}

TEST(DicomSeries, CompressedTransferSyntaxesDecode) {
    REQUIRE_REFERENCE();
    if (runShell("gdcmconv --version >/dev/null").exitCode != 0) GTEST_SKIP() << "gdcmconv (libgdcm-tools) not installed";
    std::vector<std::string> files(petByPosition().begin() + 100, petByPosition().begin() + 112);
    const fs::path plainDir = freshDir("plain");
    for (const std::string& f : files) fs::copy_file(f, plainDir / fs::path(f).filename());
    const std::vector<uint8_t> samples = readSamples(describeDicomSeries(plainDir.string(), ""));
    for (const char* flag : {"--rle", "--jpegls", "--j2k", "--jpeg --lossless"}) {
        SCOPED_TRACE(flag);
        static int n = 0;
        const fs::path dir = freshDir("ts_" + std::to_string(n++));
        for (const std::string& f : files) {
            const auto r = runShell(std::string("gdcmconv ") + flag + " " + quote(f) + " " + quote(dir / fs::path(f).filename()));
            ASSERT_EQ(r.exitCode, 0) << r.err;
        }
        EXPECT_EQ(readSamples(describeDicomSeries(dir.string(), "")), samples);
    }
}

TEST(DicomSeries, BigEndianGivesHostOrder) {
    REQUIRE_REFERENCE();
    const std::vector<std::string> files(petByPosition().begin() + 150, petByPosition().begin() + 158);
    const fs::path plain = freshDir("le");
    const fs::path big = freshDir("be");
    std::string args;
    for (const std::string& f : files) {
        fs::copy_file(f, plain / fs::path(f).filename());
        args += " " + quote(f);
    }
    const auto r = runShell(python() + " " + quote(scriptPath()) + " bigendian " + quote(big) + args);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const DenseVolume v = describeDicomSeries(big.string(), "");
    EXPECT_FALSE(v.bigEndian);
    const std::vector<uint8_t> samples = readSamples(v);
    EXPECT_EQ(samples, readSamples(describeDicomSeries(plain.string(), "")));
    EXPECT_EQ(samples, reference(big, kPetUid).raw);  // pydicom's own reading of the big-endian files
}

TEST(DicomSeries, DicomdirListsTheFiles) {
    REQUIRE_REFERENCE();
    if (runShell("gdcmgendir --version >/dev/null").exitCode != 0) GTEST_SKIP() << "gdcmgendir (libgdcm-tools) not installed";
    const std::vector<std::string> files(petByPosition().begin() + 40, petByPosition().begin() + 60);
    const fs::path dir = freshDir("dicomdir");
    const fs::path plain = freshDir("dicomdir_plain");
    copyRenamed(files, plain, 3);
    // gdcmgendir takes explicit VR little endian only, and names the files
    // relative to the folder it indexes.
    for (const auto& e : fs::directory_iterator(plain)) {
        const auto c = runShell("gdcmconv -X " + quote(e.path()) + " " + quote(dir / e.path().filename()));
        ASSERT_EQ(c.exitCode, 0) << c.err;
    }
    const auto r = runShell("cd " + quote(dir) + " && gdcmgendir -i . -o DICOMDIR");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const DenseVolume byFolder = describeDicomSeries(plain.string(), "");
    const DenseVolume byDir = describeDicomSeries((dir / "DICOMDIR").string(), "");
    EXPECT_EQ(byDir.dims, byFolder.dims);
    EXPECT_EQ(byDir.dims[2], 20);
    EXPECT_EQ(readSamples(byDir), readSamples(byFolder));
    EXPECT_EQ(byDir.origin, byFolder.origin);
    // Scanning the folder itself: the DICOMDIR is skipped, the images found.
    const DicomScan scan = scanDicom(dir.string());
    ASSERT_EQ(scan.series.size(), 1u);
    ASSERT_EQ(scan.skipped.size(), 1u);
    EXPECT_NE(scan.skipped.front().find("DICOMDIR"), std::string::npos);
}

TEST(DicomSeries, SegmentationIsRefusedClearly) {
    if (!fs::is_directory(kSeg)) GTEST_SKIP() << "../shared/data/medical absent";
    const DicomScan scan = scanDicom(kSeg.string());
    EXPECT_TRUE(scan.series.empty());
    ASSERT_EQ(scan.skipped.size(), 1u);
    EXPECT_NE(scan.skipped.front().find("DICOM-SEG segmentation"), std::string::npos) << scan.skipped.front();
    const std::string e = errorOf([] { describeDicomSeries(kSeg.string(), ""); });
    EXPECT_TRUE(oneLine(e)) << e;
    EXPECT_EQ(e.rfind(kSeg.string() + ": holds no DICOM image series", 0), 0u) << e;
    EXPECT_NE(e.find("tumor_User1_Manual_Trial1.dcm: a DICOM-SEG segmentation object"), std::string::npos) << e;
    const fs::path file = kSeg / "3DSlicer" / "tumor_User1_Manual_Trial1.dcm";
    const std::string f = errorOf([&] { describeDicomSeries(file.string(), ""); });
    EXPECT_EQ(f.rfind(file.string() + ": a DICOM-SEG segmentation object", 0), 0u) << f;
}

TEST(DicomSeries, BadInputsGiveOneLineNamingTheFile) {
    REQUIRE_REFERENCE();
    const std::vector<std::string> files(petByPosition().begin(), petByPosition().begin() + 10);

    // A file cut short inside its pixel data.
    const fs::path cut = freshDir("truncated");
    for (const std::string& f : files) fs::copy_file(f, cut / fs::path(f).filename());
    const fs::path victim = cut / fs::path(files[4]).filename();
    fs::resize_file(victim, fs::file_size(victim) - 5000);
    const std::string t = errorOf([&] { importDense(cut.string(), quietOptions()); });
    EXPECT_TRUE(oneLine(t)) << t;
    EXPECT_EQ(t.rfind(cut.string() + ": series 1 (" + kPetUid + "): " + victim.string() + " is truncated: its pixel data are 32768 bytes", 0), 0u) << t;
    // The same in RLE: found when its pixel data are decoded.
    if (runShell("gdcmconv --version >/dev/null").exitCode == 0) {
        const fs::path rle = freshDir("truncated_rle");
        for (const std::string& f : files) {
            const auto c = runShell("gdcmconv --rle " + quote(f) + " " + quote(rle / fs::path(f).filename()));
            ASSERT_EQ(c.exitCode, 0) << c.err;
        }
        const fs::path bad = rle / fs::path(files[6]).filename();
        fs::resize_file(bad, fs::file_size(bad) - 300);
        const std::string c = errorOf([&] { importDense(rle.string(), quietOptions()); });
        EXPECT_TRUE(oneLine(c)) << c;
        // Found from its element lengths when the folder is scanned, or when it is decoded.
        EXPECT_TRUE(c.rfind(bad.string() + ": slice file of " + rle.string() + ": ", 0) == 0 ||
                    c.find(bad.string() + " is corrupt: item at byte") != std::string::npos)
            << c;
    }

    // The same slice twice under another name.
    const fs::path dup = freshDir("duplicate");
    for (const std::string& f : files) fs::copy_file(f, dup / fs::path(f).filename());
    fs::copy_file(files[3], dup / "copy_of_slice");
    const std::string d = errorOf([&] { describeDicomSeries(dup.string(), ""); });
    EXPECT_TRUE(oneLine(d)) << d;
    EXPECT_EQ(d.rfind(dup.string() + ": series 1", 0), 0u) << d;
    EXPECT_NE(d.find((dup / "copy_of_slice").string()), std::string::npos) << d;
    EXPECT_NE(d.find((dup / fs::path(files[3]).filename()).string()), std::string::npos) << d;
    EXPECT_NE(d.find("same slice position"), std::string::npos) << d;

    // A folder with no DICOM in it.
    const fs::path none = freshDir("not_dicom");
    std::ofstream(none / "notes.txt") << "not an image\n";
    std::ofstream(none / "data.bin") << std::string(4096, '\x01');
    const std::string n = errorOf([&] { describeDicomSeries(none.string(), ""); });
    EXPECT_TRUE(oneLine(n)) << n;
    EXPECT_EQ(n.rfind(none.string() + ": holds no DICOM image series; 2 file(s) skipped, e.g. " + (none / "data.bin").string() + ": not a DICOM file", 0), 0u)
        << n;
    const std::string single = errorOf([&] { describeDicomSeries((none / "notes.txt").string(), ""); });
    EXPECT_EQ(single.rfind((none / "notes.txt").string() + ": not a DICOM file", 0), 0u) << single;
    const std::string missing = errorOf([&] { scanDicom((none / "absent").string()); });
    EXPECT_EQ(missing, (none / "absent").string() + ": does not exist");
    const std::string empty = errorOf([&] { scanDicom(freshDir("empty").string()); });
    EXPECT_TRUE(oneLine(empty)) << empty;
}

// Files that end inside their first DICOM element (found by
// fuzz_scan_headers): GDCM asserts on them (abort), so the element walk
// refuses them first, little- or big-endian. In-process, so an assert would end this test.
TEST(DicomSeries, AFileEndingInsideItsFirstElementIsRefusedBeforeGdcm) {
    const fs::path dir = freshDir("tiny");
    const fs::path tiny = dir / "tiny.dcm";
    struct Case {
        std::string bytes, expect;
    };
    for (const Case& c : std::vector<Case>{{std::string("\x02\x00\x00\x00", 4), "ends inside its first element"},
                                           {std::string("\xe0\x7f\x10\x00", 4), "ends inside its first element"},
                                           // big-endian, an explicit UN element whose 4-byte length is cut off
                                           {std::string("\x00\x08\x00\x0cUN\x00\x00\xc0\x00\x00", 11), "element (0008,000C) at byte 0 is cut off"}}) {
        std::ofstream(tiny, std::ios::binary).write(c.bytes.data(), std::streamsize(c.bytes.size()));
        const std::string m = errorOf([&] { scanDicom(tiny.string()); describeDicomSeries(tiny.string(), ""); });
        EXPECT_TRUE(oneLine(m)) << m;
        EXPECT_EQ(m.rfind(tiny.string() + ": ", 0), 0u) << m;
        EXPECT_NE(m.find(c.expect), std::string::npos) << m;
    }
}

TEST(DicomCli, EncodeAndInfo) {
    REQUIRE_REFERENCE();
    const fs::path dir = freshDir("cli");
    const fs::path out = dir / "adi.ssvdag";
    // Several series and no --series: one line, exit 1, nothing written.
    auto r = runCli("encode " + quote(kAdi) + " -o " + quote(out));
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("holds 4 series, pick one with --series N or UID"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_TRUE(fs::is_empty(dir));
    // The stack missing a slice converts, saying so in one warning line;
    // its active voxels are the 55 slices that have data.
    r = runCli("encode " + quote(kAdi) + " --series 2 -o " + quote(out) + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("warning: " + kAdi.string() + ": series 2: 1 missing slice"), std::string::npos) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["active_voxels"], 384 * 512 * 55);
    fs::remove(out);
    // By number and by UID.
    r = runCli("encode " + quote(kAdi) + " --series 3 -o " + quote(out) + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["active_voxels"], 256 * 256);
    r = runCli("encode " + quote(kAdi) + " --series " + kRelCbfUid + " -o " + quote(dir / "relcbf.ssvdag"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    // The PET folder has one series: no --series needed.
    r = runCli("encode " + quote(kPet) + " -o " + quote(dir / "pet.ssvdag"));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    // --series is for DICOM only.
    const fs::path nrrd = fs::path(VDBDAG_SHARED_DATA) / "dense" / "FLAIR.nrrd";
    r = runCli("encode " + quote(nrrd) + " --series 1 -o " + quote(dir / "flair.ssvdag"));
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("--series applies to DICOM inputs only"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "flair.ssvdag"));

    // info lists the series and the skipped files.
    r = runCli("info " + quote(kAdi) + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json info = nlohmann::json::parse(r.out);
    EXPECT_EQ(info["format"], "dicom");
    ASSERT_EQ(info["series"].size(), 4u);
    EXPECT_EQ(info["skipped_files"], 3);
    EXPECT_EQ(info["series"][1]["uid"], kT2Uid);
    EXPECT_EQ(info["series"][1]["slices"], 56);
    EXPECT_EQ(info["series"][1]["missing_slices"], 1);
    EXPECT_EQ(info["series"][1]["dims"], nlohmann::json({384, 512, 56}));
    EXPECT_EQ(info["series"][1]["convertible"], true);
    EXPECT_EQ(info["series"][2]["convertible"], true);
    EXPECT_EQ(info["series"][2]["description"], "Perfusion_Weighted");
    r = runCli("info " + quote(kAdi));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("4 series, 3 file(s) skipped"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("3) " + kPerfUid + "  MR  \"Perfusion_Weighted\"  1 slices  256x256x1 u16"), std::string::npos) << r.out;
}

// A file that declares a 3 GB element in a few hundred kilobytes is refused
// from its element headers, before GDCM would allocate the 3 GB: `info`
// under a 1.5 GB address-space cap skips it with the reason, and a slice
// reader given it names it.
TEST(DicomSeries, AnElementLongerThanItsFileIsRefusedBeforeItIsAllocated) {
    REQUIRE_REFERENCE();
    const fs::path dir = freshDir("huge_element");
    const std::string source = petByPosition().front();
    std::ifstream in(source, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    // Implicit VR little endian: (0010,0010) Patient's Name, then a 4-byte length.
    const std::string tag("\x10\x00\x10\x00", 4);
    const size_t at = bytes.find(tag);
    ASSERT_NE(at, std::string::npos);
    const uint32_t huge = 0xBF000000u;
    std::memcpy(&bytes[at + 4], &huge, 4);
    const fs::path bad = dir / "huge.dcm";
    std::ofstream(bad, std::ios::binary) << bytes;
    const auto r = runShell("ulimit -v 1500000; " + std::string(VDBDAG_BINARY) + " info " + quote(dir) + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;  // no series, one file skipped with its reason
    const nlohmann::json info = nlohmann::json::parse(r.out);
    EXPECT_EQ(info["series"].size(), 0u);
    ASSERT_EQ(info["skipped"].size(), 1u);
    EXPECT_NE(info["skipped"][0].get<std::string>().find("claims 3204448256 bytes"), std::string::npos) << info.dump();
    const DicomScan scan = [&] {
        try {
            return scanDicom(bad.string());
        } catch (const Error& e) {
            ADD_FAILURE() << e.what();
            return DicomScan{};
        }
    }();
    ASSERT_EQ(scan.skipped.size(), 1u);
    EXPECT_NE(scan.skipped[0].find("element (0010,0010)"), std::string::npos) << scan.skipped[0];
    EXPECT_NE(scan.skipped[0].find("claims 3204448256 bytes"), std::string::npos) << scan.skipped[0];
}

// Forged headers from fuzz_scan_headers (issue 38 #6), in-process so that an
// abort ends this test: a Photometric Interpretation no greyscale has made
// GDCM's image reader assert (gdcmPixmapReader.cxx) while the slices were
// read; native pixel data are now read without it and the series is refused
// in one line. Items, delimiters and item tags where DICOM has none are
// refused by the element walk before GDCM parses the file (an item where an
// element belongs made GDCM's header reader assert).
TEST(DicomSeries, ForgedHeadersAreRefusedBeforeGdcmAssertsOnThem) {
    REQUIRE_REFERENCE();
    const std::string source = petByPosition().front();
    std::ifstream in(source, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    struct Case {
        std::string from, to, expect;
    };
    for (const Case& c : std::vector<Case>{{"MONOCHROME2 ", "PALETTE COL ", "Photometric Interpretation 'PALETTE COL' is no greyscale"},
                                           {std::string("\x10\x00\x10\x00", 4), std::string("\xfe\xff\xdd\xe0", 4), "a delimiter (FFFE,E0DD) at byte"},
                                           {std::string("\x10\x00\x10\x00", 4), std::string("\xfe\xff\x00\x00", 4), "unknown item tag (FFFE,0000)"},
                                           // GDCM aborts on it (gdcmImplicitDataElement.txx:66, also in gdcmdump)
                                           {std::string("\x10\x00\x10\x00", 4), std::string("\xfe\xff\x00\xe0", 4), "an item (FFFE,E000) at byte"},
                                           // GDCM guessed its way through it and allocated 2.9 GB (a 483-byte file)
                                           {std::string("1.2.840.10008.1.2\0", 18), std::string("1.2.841.10008.1.2\0", 18), "its transfer syntax '1.2.841.10008.1.2'"},
                                           // an element cut off after its tag: GDCM aborts (gdcmExplicitDataElement.txx:104)
                                           {"", std::string("\x10\x00\x10\x00\x50", 5), "the file ends inside an element"}}) {
        const fs::path dir = freshDir("forged_header");
        std::string forged = bytes;
        if (c.from.empty()) {
            forged += c.to;  // appended
        } else {
            const size_t at = forged.find(c.from);
            ASSERT_NE(at, std::string::npos) << c.expect;
            forged.replace(at, c.to.size(), c.to);
        }
        const fs::path bad = dir / "forged.dcm";
        std::ofstream(bad, std::ios::binary) << forged;
        const std::string m = errorOf([&] {
            const DenseVolume v = describeDicomSeries(bad.string(), "");
            std::vector<uint8_t> slab;
            openDicomSlices(v)->readSlices(v.dims[2], slab);
        });
        EXPECT_TRUE(oneLine(m)) << m;
        EXPECT_EQ(m.rfind(bad.string() + ": ", 0), 0u) << m;
        EXPECT_NE(m.find(c.expect), std::string::npos) << m;
    }
}

// A list of files (extensionless, named on the command line in no useful
// order, one of them twice) is one set: its series equals pydicom's stack
// of the folder; a non-DICOM file among the inputs is refused in one line.
TEST(DicomCli, AListOfFilesIsOneSet) {
    REQUIRE_REFERENCE();
    const Reference ref = reference(kPet, kPetUid);
    const std::vector<std::string>& ordered = petByPosition();
    const fs::path dir = freshDir("list");
    std::vector<std::string> files;
    for (size_t i = 0; i < ordered.size(); ++i) {
        const fs::path to = dir / ("slice" + std::to_string((i * 7919) % ordered.size()));  // no extension: found by its DICM prefix
        fs::copy_file(ordered[i], to);
        files.push_back(to.string());
    }
    std::mt19937 rng(5);
    std::shuffle(files.begin(), files.end(), rng);
    files.push_back(files.front());
    DenseImportOptions o = quietOptions();
    o.moreInputs.assign(files.begin() + 1, files.end());
    const DenseVolume v = describeDense(files.front(), o);
    expectGeometry(v, ref.meta);
    EXPECT_EQ(readSamples(v), ref.raw);
    EXPECT_EQ(v.gridName, "list");

    std::string args;
    for (const std::string& f : files) args += " " + quote(f);
    auto r = runCli("info" + args + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json info = nlohmann::json::parse(r.out);
    ASSERT_EQ(info["series"].size(), 1u);
    EXPECT_EQ(info["series"][0]["uid"], kPetUid);
    EXPECT_EQ(info["series"][0]["slices"], int(ordered.size()));
    const fs::path out = workDir() / "list.ssvdag";
    r = runCli("encode" + args + " -o " + quote(out) + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["active_voxels"], v.sampleCount());
    // An output that is one of the inputs is refused, even with -f.
    r = runCli("encode" + args + " -f -o " + quote(files.back()));
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("is the input"), std::string::npos) << r.err;
    // A NRRD among DICOM inputs: one line naming it, nothing written.
    const fs::path nrrd = fs::path(VDBDAG_SHARED_DATA) / "dense" / "FLAIR.nrrd";
    r = runCli("encode" + args + " " + quote(nrrd) + " -o " + quote(workDir() / "mixed.ssvdag"));
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(nrrd.string() + ": not DICOM"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(workDir() / "mixed.ssvdag"));
}

// A file that starts like no DICOM at all (no preamble, no group 0002 or
// 0008 first) is walked too: GDCM parses it as a dataset anyway, and
// allocated 1.8 GB for these 106 bytes (found by fuzz_scan_headers). Under
// a 1.5 GB address-space cap it is skipped as not DICOM, with the reason.
TEST(DicomSeries, BytesThatReadAsAHugeElementAreNotDicomAndCostNothing) {
    const fs::path dir = freshDir("not_dicom_huge");
    // (Its OB's reserved bytes are zero: non-zero ones are refused before the length is read.)
    std::ofstream(dir / "junk.bin", std::ios::binary) << std::string("dataOB", 6) + std::string(2, '\0') + "le" + std::string(95, '\x17') + "[";
    const auto r = runShell("ulimit -v 1500000; " + std::string(VDBDAG_BINARY) + " info " + quote(dir) + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json info = nlohmann::json::parse(r.out);
    EXPECT_EQ(info["series"].size(), 0u);
    ASSERT_EQ(info["skipped"].size(), 1u);
    const std::string reason = info["skipped"][0].get<std::string>();
    EXPECT_EQ(reason.rfind((dir / "junk.bin").string() + ": not a DICOM file (no DICM preamble", 0), 0u) << reason;
    EXPECT_NE(reason.find("its first element (6164,6174) is of neither"), std::string::npos) << reason;
}
