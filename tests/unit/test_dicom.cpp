// DICOM input (vdb_bridge/DicomSeries.h): the shared series come back
// sample for sample and with the same geometry as pydicom gives them
// (tests/tools/dicom_reference.py stacks the files by ImagePositionPatient .
// normal, never with vdbdag code); series are listed and picked, mixes are
// refused in one line, slices are ordered by position rather than by name,
// rescales are applied, a segmentation is refused in one line, the command
// line encodes and lists them. Bad and forged inputs:
// test_dicom_refusals.cpp. Skipped when ../shared/data or python3 with
// pydicom is missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <random>

#include <nlohmann/json.hpp>

#include "tests/unit/BuildPaths.h"
#include "src/util/Error.h"
#include "tests/unit/CliRunner.h"
#include "tests/unit/DicomTestSupport.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/DicomSeries.h"

namespace fs = std::filesystem;
using namespace vdbdag;
using namespace vdbdag::bridge;
using namespace vdbdag::testing::dicom;
using vdbdag::testing::runCli;
using vdbdag::testing::runShell;

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
