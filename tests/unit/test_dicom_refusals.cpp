// DICOM input refused in one line naming the file, nothing read past what
// the file holds (vdb_bridge/DicomSeries.h): truncated slices (native and
// RLE), duplicates, folders without DICOM, files ending inside an element,
// elements longer than their file, forged headers GDCM asserted on, bytes
// that read as a huge element. Helpers: DicomTestSupport.h.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

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
using vdbdag::testing::runShell;

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
