// The element walk that guards GDCM (vdb_bridge/detail/DicomElementWalk.h)
// on forged files: Debian's GDCM asserts (aborts) on some and allocates
// what others claim. In-process, so that an abort ends the test rather than
// passing as a refusal. Needs no ../shared data.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "tests/unit/BuildPaths.h"
#include "src/util/Error.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/DicomSeries.h"
#include "vdb_bridge/detail/DicomElementWalk.h"
#include "vdb_bridge/detail/DicomSequence.h"

namespace fs = std::filesystem;
using namespace vdbdag;
using namespace vdbdag::bridge;

namespace {

// An explicit-VR little-endian element with a 2-byte length.
std::string element(uint16_t group, uint16_t elem, const char* vr, const std::string& value) {
    std::string e;
    e += char(group & 0xFF), e += char(group >> 8), e += char(elem & 0xFF), e += char(elem >> 8);
    e += vr;
    e += char(value.size() & 0xFF), e += char(value.size() >> 8);
    return e + value;
}

std::string quote(const fs::path& p) { return "'" + p.string() + "'"; }

fs::path write(const std::string& name, const std::string& bytes) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_dicom_walk_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return dir / name;
}

} // namespace

// An element cut off after its tag: GDCM aborted on one in
// VR16ExplicitDataElement::ReadPreValue (gdcmVR16ExplicitDataElement.txx:146;
// found by fuzz_scan_headers in tests/fuzz/regressions/scan_headers/
// dicom_cut_after_tag_abort). Here a data set without preamble that starts
// as DICOM does (group 0008), explicit VR, and ends in 5 bytes: a tag and
// one byte of a VR. The walk refuses it, so the scan skips it saying why;
// without those 5 bytes it walks, and GDCM reads it.
TEST(DicomWalk, AnElementCutOffAfterItsTagIsRefused) {
    std::string bytes = element(0x0008, 0x0016, "UI", std::string("1.2.840.10008.5.1.4.1.1.2\0", 26));
    bytes += element(0x0008, 0x0060, "CS", "CT");
    bytes += element(0x0028, 0x0010, "US", std::string("\xff\xff", 2));
    bytes += std::string("\x28\0\x10\0\0", 5);  // a tag and one byte
    const fs::path file = write("cut.dcm", bytes);
    const std::string problem = detail::elementLengthProblem(file.string(), true);
    EXPECT_EQ(problem.rfind("the file ends inside an element (its last 5 bytes", 0), 0u) << problem;
    const DicomScan scan = scanDicom(file.parent_path().string());
    EXPECT_TRUE(scan.series.empty());
    ASSERT_EQ(scan.skipped.size(), 1u);
    EXPECT_NE(scan.skipped[0].find("the file ends inside an element"), std::string::npos) << scan.skipped[0];
    fs::remove(file);
    const fs::path whole = write("whole.dcm", bytes.substr(0, bytes.size() - 5));
    EXPECT_EQ(detail::elementLengthProblem(whole.string(), true), "");
    const DicomScan again = scanDicom(whole.parent_path().string());
    ASSERT_EQ(again.skipped.size(), 1u);  // its Rows alone make no image: skipped, saying so
    EXPECT_NE(again.skipped[0].find("no image"), std::string::npos) << again.skipped[0];
    fs::remove_all(file.parent_path());
}

// Under an explicit transfer syntax an element whose VR bytes are no VR is
// refused: GDCM guesses how to read it, and allocated what it read as the
// length (1.7 GB for 462 bytes: tests/fuzz/regressions/scan_headers/
// dicom_element_without_vr_oom). A data set whose first element has no VR
// is read as implicit (a writer that declared the wrong syntax).
TEST(DicomWalk, AnElementWithoutAVrUnderAnExplicitSyntaxIsRefused) {
    std::string bytes = element(0x0008, 0x0016, "UI", std::string("1.2.840.10008.5.1.4.1.1.2\0", 26));
    bytes += element(0x0008, 0x0060, "CS", "CT");
    bytes += std::string("\x28\0\x00\x01\x10\0\0\0", 8);  // (0028,0100), VR bytes 10 00
    bytes += element(0x0028, 0x0010, "US", std::string("\x02\0", 2));
    const fs::path file = write("novr.dcm", bytes);
    EXPECT_EQ(detail::elementLengthProblem(file.string()), "element (0028,0100) at byte 44 has no valid VR under an explicit transfer syntax");
    // The same element first, then implicit elements: an implicit data set.
    std::string implicit = std::string("\x08\0\x16\0\x1a\0\0\0", 8) + std::string("1.2.840.10008.5.1.4.1.1.2\0", 26);
    implicit += std::string("\x28\0\x10\0\x02\0\0\0\x02\0", 10);
    const fs::path plain = write("implicit.dcm", implicit);
    EXPECT_EQ(detail::elementLengthProblem(plain.string()), "");
    fs::remove_all(file.parent_path());
}

// The DICOM inputs fuzz_scan_headers failed on (tests/fuzz/regressions,
// format byte 4; its README says what each did). All but the last start
// like no DICOM (no preamble and a first group neither 0002 nor 0008, or a
// DICM prefix without the file meta group after it), which GDCM parses by
// guessing its byte order and VRs: the walk refuses them before GDCM sees
// them. Others walk and are refused when their header is read, before
// GDCM's image reader sees their Recognition Code, overlay or curve groups
// or icon; the walk refuses the rest. `vdbdag info` of each file and of its
// folder, under a 1.5 GB address-space cap, lists it as skipped.
// GE's private transfer syntax 1.2.840.113619.5.2 ("implicit VR big
// endian": GDCM reads its data set as implicit VR, only its pixels are
// big-endian) is walked as implicit, not refused as an explicit data set
// without VRs (a regression of ee789f3 found by review).
TEST(DicomWalk, GesPrivateImplicitSyntaxIsWalkedAsImplicit) {
    const auto implicitElement = [](uint16_t group, uint16_t elem, const std::string& value) {
        std::string e;
        e += char(group & 0xFF), e += char(group >> 8), e += char(elem & 0xFF), e += char(elem >> 8);
        for (int b = 0; b < 4; ++b) e += char((value.size() >> (8 * b)) & 0xFF);
        return e + value;
    };
    // A preamble, DICM, the meta group (its length, the transfer syntax),
    // then two implicit-VR elements.
    const auto file = [&](const std::string& syntax) {
        const std::string meta = element(0x0002, 0x0010, "UI", syntax);
        const uint32_t n = uint32_t(meta.size());
        const std::string length{char(n & 0xFF), char(n >> 8 & 0xFF), char(n >> 16 & 0xFF), char(n >> 24)};
        return std::string(128, '\0') + "DICM" + element(0x0002, 0x0000, "UL", length) + meta +
               implicitElement(0x0008, 0x0016, std::string("1.2.840.10008.5.1.4.1.1.2\0", 26)) + implicitElement(0x0008, 0x0060, "MR");
    };
    const fs::path ge = write("ge.dcm", file(std::string("1.2.840.113619.5.2", 18)));
    EXPECT_EQ(detail::elementLengthProblem(ge.string(), true), "");
    // The same elements under explicit VR little endian: no VR where one belongs.
    const std::string refused = detail::elementLengthProblem(write("explicit.dcm", file(std::string("1.2.840.10008.1.2.1\0", 20))).string(), true);
    EXPECT_NE(refused.find("has no valid VR under the explicit transfer syntax 1.2.840.10008.1.2.1"), std::string::npos) << refused;
    fs::remove_all(ge.parent_path());
}

TEST(DicomWalk, TheFuzzRegressionsAreRefusedBeforeGdcmAndCostNothing) {
    const fs::path dir = fs::path(VDBDAG_SOURCE_DIR) / "tests/fuzz/regressions/scan_headers";
    const std::pair<const char*, const char*> cases[] = {{"dicom_cut_after_tag_abort", "its first element (0000,0000) is of neither"},
                                                         {"dicom_element_without_vr_oom", "its first element (0000,0000) is of neither"},
                                                         {"dicom_open_pixel_data_abort", "its first element (7FE0,0010) is of neither"},
                                                         {"dicom_guessed_big_endian_oom", "its first element (0028,0103) is of neither"},
                                                         {"dicom_no_meta_group_oom", "no file meta group after the DICM prefix: its first element is (FFFF,FFFF)"},
                                                         // walks, but is refused when its header is read
                                                         {"dicom_recognition_code_abort", "its Recognition Code (0008,0010) '1.2.3.4.5.6.7' is none"},
                                                         {"dicom_meta_explicit_without_vr_abort",
                                                          "has no valid VR under the explicit transfer syntax 1.2.840.10008.1.2.5 its file meta group declares"},
                                                         {"dicom_meta_sequence_abort", "is a sequence (VR SQ)"},
                                                         {"dicom_text_vr_abort", "element (0008,0016) has VR OV, which has no text (GDCM's StringFilter aborts on it)"},
                                                         {"dicom_orientation_vr_abort",
                                                          "element (0020,0037) Image Orientation (Patient) at byte 250 has VR AS, which GDCM's image reader aborts on"},
                                                         // walk, but are refused when their header is read (RLE: GDCM's image reader would decode them)
                                                         {"dicom_overlay_element_abort", "overlay group 6000 holds element (6000,1001), which GDCM's image reader aborts on"},
                                                         {"dicom_overlay_groups_abort", "17 overlay groups (60xx), more than the 16 GDCM's image reader takes"},
                                                         {"dicom_overlay_origin_short_abort", "element (6000,0050) Overlay Origin holds 1 byte, too few for the first of its 2 values"},
                                                         {"dicom_icon_palette_subscript_abort",
                                                          "Red Palette Color Lookup Table Descriptor (0028,1101) whose first mapped value is 16, which GDCM's image reader aborts on"},
                                                         {"dicom_icon_descriptor_short_abort", "Red Palette Color Lookup Table Descriptor (0028,1101) of 2 bytes, fewer than its 3 values"},
                                                         {"dicom_icon_empty_photometric_crash", "its Icon Image Sequence (0088,0200) has an empty Photometric Interpretation (0028,0004)"},
                                                         {"dicom_icon_samples_per_pixel_abort",
                                                          "its Icon Image Sequence (0088,0200) has Samples per Pixel (0028,0002) 79, which GDCM's image reader aborts on"},
                                                         {"dicom_curve_element_abort", "curve group 5000 holds element (5000,0050), which GDCM's image reader aborts on"},
                                                         {"dicom_overlays_in_and_out_of_pixels_abort",
                                                          "overlay group 6020 keeps its Overlay Data and overlay group 601E does not (none, or no Rows x Columns"},
                                                         {"dicom_overlay_size_oom", "overlay group 600C of 47108x24580 pixels, which GDCM's image reader unpacks"},
                                                         {"dicom_not_image_storage_abort",
                                                          "GDCM's image reader would take its SOP class for 1.2.840.10008.3.1.2.3.1"},
                                                         {"dicom_samples_per_pixel_values_abort",
                                                          "Samples per Pixel (0028,0002) holds 8 values where DICOM has one (GDCM's image reader takes the first, 21333"},
                                                         // refused by the walk
                                                         {"dicom_pixel_data_od_undefined_abort",
                                                          "element (7FE0,0010) at byte 936 has an undefined length under VR OD (GDCM takes it for OB, OW or UN pixel data only)"},
                                                         // refused when its header is read (DicomSequence.h)
                                                         {"dicom_un_icon_sequence_oom",
                                                          "its Icon Image Sequence (0088,0200) is a sequence stored as 962 bytes (UN) that does not read as implicit VR "
                                                          "little endian (DICOM CP-246)"},
                                                         {"dicom_un_icon_sequence_swapped_oom",
                                                          "its Icon Image Sequence (0088,0200) is a sequence stored as 962 bytes (UN) that does not read as implicit VR "
                                                          "little endian (DICOM CP-246)"},
                                                         {"dicom_odd_item_length_abort",
                                                          "the item at byte 316 holds elements of odd total length (its element (0008,1150) at byte 324 is 25 bytes long)"}};
    for (const auto& [name, why] : cases) {
        std::ifstream in(dir / name, std::ios::binary);
        const std::string input((std::istreambuf_iterator<char>(in)), {});
        ASSERT_GT(input.size(), 1u) << name;
        ASSERT_EQ(input[0], '\4') << name << ": a DICOM input";
        const fs::path file = write(std::string(name) + ".dcm", input.substr(1));
        const std::string problem = detail::elementLengthProblem(file.string());  // the whole file, as a lone file's DICOMDIR check reads it
        const bool walkRefuses = problem.find(why) != std::string::npos;
        EXPECT_TRUE(walkRefuses || problem.empty()) << name << ": " << problem;
        // The file alone (the fuzz target's call) and its folder: skipped,
        // saying why (the folder's scan stops its walk at the pixel data,
        // so the third is skipped there as no image).
        for (const fs::path& input : {file, file.parent_path()}) {
            const auto r = vdbdag::testing::runShell("ulimit -v 1500000; " + std::string(VDBDAG_BINARY) + " info " + quote(input) + " --json");
            ASSERT_EQ(r.exitCode, 0) << name << ": " << r.err;
            const nlohmann::json info = nlohmann::json::parse(r.out);
            EXPECT_EQ(info["series"].size(), 0u) << name;
            ASSERT_EQ(info["skipped"].size(), 1u) << name;
            const std::string reason = info["skipped"][0].get<std::string>();
            EXPECT_EQ(reason.rfind(file.string() + ": ", 0), 0u) << reason;
            if (!walkRefuses && input == file) {
                EXPECT_NE(reason.find(why), std::string::npos) << name << ": " << reason;
            }
        }
        fs::remove_all(file.parent_path());
    }
}

// RLE Lossless pixel data (PS3.5 annex G) that GDCM's RLECodec would decode
// unchecked (vdb_bridge/detail/DicomRle.h). The base is the fuzz finding
// tests/fuzz/regressions/scan_headers/dicom_rle_segment_count_crash: a 4x4
// 16-bit RLE file whose header declares 0x02000002 segments, so GDCM read
// its 15 segment offsets far out of bounds (SIGSEGV while encoding). With the
// count set to 2 it is a valid file: segment 1 holds the high bytes, segment
// 2 the low ones, each 16 literal bytes after a control byte 15 (at bytes 64
// and 82 of the 100-byte fragment), so pixel i is hi[i] << 8 | lo[i], read
// off the bytes by hand. Every forged variant is refused with an
// vdbdag::Error naming the problem, in-process (a crash ends the test).
TEST(DicomRle, ForgedRleHeadersAreRefusedAndAValidOneDecodesByHand) {
    std::ifstream in(fs::path(VDBDAG_SOURCE_DIR) / "tests/fuzz/regressions/scan_headers/dicom_rle_segment_count_crash", std::ios::binary);
    const std::string input((std::istreambuf_iterator<char>(in)), {});
    ASSERT_EQ(input.size(), 700u);
    const std::string base = input.substr(1);
    const size_t fragment = base.find(std::string("\xFE\xFF\x00\xE0\x64\x00\x00\x00", 8)) + 8;  // the 100-byte fragment's first byte
    ASSERT_LT(fragment, base.size());
    const auto patch = [&](const std::string& from, size_t at, const std::string& bytes) {
        std::string s = from;
        s.replace(fragment + at, bytes.size(), bytes);
        return s;
    };
    const auto le32 = [](uint32_t v) { return std::string{char(v & 0xFF), char(v >> 8 & 0xFF), char(v >> 16 & 0xFF), char(v >> 24)}; };
    const std::string valid = patch(base, 0, le32(2));
    const auto patched = [&](size_t at, const std::string& bytes) { return patch(valid, at, bytes); };
    const auto read = [&](const std::string& bytes) {
        const fs::path file = write("rle.dcm", bytes);
        const DenseVolume v = describeDicomSeries(file.string(), "");
        std::vector<uint8_t> out;
        openSliceReader(v)->readSlices(v.dims[2], out);
        return out;
    };
    // Valid: the values by hand.
    const std::vector<uint8_t> samples = read(valid);
    ASSERT_EQ(samples.size(), 32u);
    const uint8_t hi[16] = {0, 0, 0, 1, 1, 1, 2, 2, 3, 3, 3, 4, 4, 5, 5, 5};
    const uint8_t lo[16] = {0x00, 0x64, 0xc8, 0x2c, 0x90, 0xf4, 0x58, 0xbc, 0x20, 0x84, 0xe8, 0x4c, 0xb0, 0x14, 0x78, 0xdc};
    for (size_t i = 0; i < 16; ++i) EXPECT_EQ(samples[2 * i] | samples[2 * i + 1] << 8, hi[i] << 8 | lo[i]) << i;
    const std::pair<std::string, std::string> forged[] = {
        {base, "an RLE header of 33554434 segments where its pixels need 2"},
        {patched(0, le32(0)), "an RLE header of 0 segments where its pixels need 2"},
        {patched(0, le32(16)), "an RLE header of 16 segments where its pixels need 2"},
        {patched(0, le32(2) + le32(65)), "RLE segment 1 starts at byte 65 of a 100-byte frame (the first must start at byte 64)"},
        {patched(0, le32(2) + le32(64) + le32(100)), "RLE segment 2 starts at byte 100 of a 100-byte frame (not inside the frame after"},
        {patched(0, le32(2) + le32(64) + le32(64)), "RLE segment 2 starts at byte 64 of a 100-byte frame (not inside the frame after"},
        {patched(64, "\x10"), "RLE segment 1 decodes to 17 bytes, not the 16 of its share of the frame"},
        {patched(82, "\x7f"), "RLE segment 2 runs past the end of its frame after 0 of its 16 bytes"},
        {patched(64, "\x0e"), "RLE segment 1 decodes to 21 bytes"},  // 15 literal bytes, then the 16th (5) read as a control byte: 6 more
    };
    for (const auto& [bytes, why] : forged) {
        try {
            read(bytes);
            ADD_FAILURE() << "not refused: " << why;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
        }
    }
    // The finding itself through the command line: one line naming the
    // file and the problem, a non-zero exit, nothing written.
    const fs::path file = write("finding.dcm", base);
    const fs::path out = file.parent_path() / "finding.ssvdag";
    const auto r = vdbdag::testing::runShell(std::string(VDBDAG_BINARY) + " encode " + quote(file) + " -o " + quote(out));
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find(file.string() + ": slice file of "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("an RLE header of 33554434 segments"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    fs::remove_all(file.parent_path());
}

// The SOP class check of a file GDCM's image reader decodes (an RLE file:
// the valid one of the test above), through the three ways
// PixmapReader::Read goes when the file meta header's class is unknown: the
// data set's class is CT, and the file reads, its pixels as by hand; both
// unknown, and GDCM gives the file up itself (one line, no abort); the data
// set's class one that a space cuts to a non-image class (Detached Study
// Management, the fuzz finding dicom_not_image_storage_abort), refused by
// the check naming it, where GDCM's reader asserted.
TEST(DicomWalk, AnUnknownSopClassIsReadRefusedOrGivenUpAsGdcmWould) {
    std::ifstream in(fs::path(VDBDAG_SOURCE_DIR) / "tests/fuzz/regressions/scan_headers/dicom_rle_segment_count_crash", std::ios::binary);
    std::string valid = std::string((std::istreambuf_iterator<char>(in)), {}).substr(1);
    const size_t fragment = valid.find(std::string("\xFE\xFF\x00\xE0\x64\x00\x00\x00", 8)) + 8;
    ASSERT_LT(fragment, valid.size());
    valid.replace(fragment, 4, std::string("\x02\x00\x00\x00", 4));  // two segments: the valid file
    const std::string ct = "1.2.840.10008.5.1.4.1.1.2";
    const auto withClasses = [&](const std::string& name, const std::string& meta, const std::string& dataSet) {
        std::string s = valid;
        EXPECT_EQ(s.substr(166, ct.size()), ct);  // (0002,0002) and (0008,0016)
        EXPECT_EQ(s.substr(248, ct.size()), ct);
        s.replace(166, ct.size(), meta);
        s.replace(248, ct.size(), dataSet);
        return write(name, s);
    };
    const std::string unknown = "1.2.840.10008.5.1.4.1.9.9";   // no class GDCM knows
    const std::string cutToStudy = "1.2.840.10008.3.1.2.3.1 2";  // "1.2.840.10008.3.1.2.3.1" once cut at the space
    ASSERT_EQ(unknown.size(), ct.size());
    ASSERT_EQ(cutToStudy.size(), ct.size());
    const DenseVolume v = describeDicomSeries(withClasses("meta_unknown.dcm", unknown, ct).string(), "");
    std::vector<uint8_t> out;
    openSliceReader(v)->readSlices(v.dims[2], out);
    ASSERT_EQ(out.size(), 32u);
    EXPECT_EQ(out[2 * 15] | out[2 * 15 + 1] << 8, 5 << 8 | 0xdc);  // the last pixel, as read by hand above
    const std::pair<fs::path, std::string> refused[] = {
        {withClasses("both_unknown.dcm", unknown, unknown), "GDCM cannot read it as a DICOM image"},
        {withClasses("study_class.dcm", unknown, cutToStudy), "GDCM's image reader would take its SOP class for 1.2.840.10008.3.1.2.3.1"},
    };
    for (const auto& [file, why] : refused) {
        try {
            const DenseVolume w = describeDicomSeries(file.string(), "");
            openSliceReader(w)->readSlices(w.dims[2], out);
            ADD_FAILURE() << "not refused: " << file;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
        }
    }
    fs::remove_all(fs::temp_directory_path() / ("vdbdag_dicom_walk_" + std::to_string(::getpid())));
}

// An element of undefined length under an explicit VR GDCM reads it by:
// SQ or UN (a sequence), Pixel Data of OB, OW or UN (fragments). Any other
// VR asserted in ExplicitDataElement::ReadValue (the fuzz finding
// dicom_pixel_data_od_undefined_abort: Pixel Data of VR OD). The finding
// with its VR made OB walks; the same bytes under another tag, an OB
// element of undefined length that is no pixel data, are refused.
TEST(DicomWalk, UndefinedLengthsOnlyUnderTheVrsGdcmReadsThemBy) {
    std::ifstream in(fs::path(VDBDAG_SOURCE_DIR) / "tests/fuzz/regressions/scan_headers/dicom_pixel_data_od_undefined_abort", std::ios::binary);
    const std::string base = std::string((std::istreambuf_iterator<char>(in)), {}).substr(1);
    const size_t at = base.find(std::string("\xE0\x7F\x10\x00OD", 6));
    ASSERT_NE(at, std::string::npos);
    std::string ob = base;
    ob[at + 4] = 'O', ob[at + 5] = 'B';
    const size_t end = ob.rfind(std::string("\xFE\xFF\xDD\xE0", 4));  // its delimiter's length (60,160) made 0, as DICOM has it
    ASSERT_NE(end, std::string::npos);
    ob.replace(end + 4, 4, std::string(4, '\0'));
    EXPECT_EQ(detail::elementLengthProblem(write("ob.dcm", ob).string()), "");
    std::string other = ob;
    other[at] = '\x09', other[at + 1] = '\x00';  // (0009,0010): a private element, not pixel data
    const std::string refused = detail::elementLengthProblem(write("other.dcm", other).string());
    EXPECT_NE(refused.find("element (0009,0010) at byte 936 has an undefined length under VR OB (GDCM takes it for a sequence of VR SQ or UN only)"),
              std::string::npos)
        << refused;
    fs::remove_all(fs::temp_directory_path() / ("vdbdag_dicom_walk_" + std::to_string(::getpid())));
}

// The delimiter that ends encapsulated pixel data with a length: GDCM reads
// it as one more fragment and allocated its 3 GB before reading
// (Fragment::ReadValue; the fuzz finding dicom_fragments_delimiter_length_oom,
// 1,600 bytes). The walk refuses it, so `info` lists the series as not
// convertible and `encode` stops naming the file; with the length 0 that
// DICOM gives every delimiter the file walks.
TEST(DicomWalk, ADelimiterWithALengthAfterPixelFragmentsIsRefused) {
    std::ifstream in(fs::path(VDBDAG_SOURCE_DIR) / "tests/fuzz/regressions/scan_headers/dicom_fragments_delimiter_length_oom", std::ios::binary);
    const std::string bytes = std::string((std::istreambuf_iterator<char>(in)), {}).substr(1);
    const std::string why = "the delimiter (FFFE,E0DD) at byte 1094 that ends encapsulated pixel data claims 3137339392 bytes (DICOM gives it 0)";
    const fs::path file = write("delimiter.dcm", bytes);
    EXPECT_NE(detail::elementLengthProblem(file.string()).find(why), std::string::npos) << detail::elementLengthProblem(file.string());
    const fs::path out = file.parent_path() / "delimiter.ssvdag";
    const auto r = vdbdag::testing::runShell("ulimit -v 1500000; " + std::string(VDBDAG_BINARY) + " encode " + quote(file) + " -o " + quote(out));
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find(file.string() + " is corrupt: " + why), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
    std::string zero = bytes;
    ASSERT_EQ(zero.substr(1094, 4), std::string("\xFE\xFF\xDD\xE0", 4));
    zero.replace(1098, 4, std::string(4, '\0'));
    EXPECT_EQ(detail::elementLengthProblem(write("zero.dcm", zero).string()), "");
    fs::remove_all(file.parent_path());
}

// A sequence GDCM keeps as bytes (stored as UN, or of defined length in an
// implicit-VR file) is parsed (DataElement::GetValueAsSQ) only where GDCM's
// first reading, implicit VR little endian, holds it: every declared value
// length within kMaxUnheldBytes past its bytes (vdb_bridge/detail/
// DicomSequence.h; the fuzz findings dicom_un_icon_sequence_oom and
// dicom_un_icon_sequence_swapped_oom allocated 4.2 GB and 850 MB in the
// other readings GDCM tries after it on a UN sequence). GDCM itself is the
// reference for the sequences let through: it reads their one item and its
// three elements.
TEST(DicomSequence, ASequenceKeptAsBytesIsParsedOnlyWhereGdcmHoldsWhatItAllocates) {
    const auto le16 = [](uint16_t v) { return std::string{char(v & 0xFF), char(v >> 8)}; };
    const auto le32 = [&](uint32_t v) { return le16(uint16_t(v)) + le16(uint16_t(v >> 16)); };
    const auto implicitElement = [&](uint16_t g, uint16_t e, uint32_t declared, const std::string& value) { return le16(g) + le16(e) + le32(declared) + value; };
    const auto item = [&](const std::string& elements) { return le16(0xFFFE) + le16(0xE000) + le32(uint32_t(elements.size())) + elements; };
    const std::string samples = std::string("\x01\x00", 2), photometric = "MONOCHROME2 ";
    // An OW element with a 4-byte length: the explicit form of palette data.
    const auto ow = [&](uint32_t declared, const std::string& value) { return le16(0x0028) + le16(0x1201) + "OW" + std::string(2, '\0') + le32(declared) + value; };
    const std::string explicitItem = item(element(0x0028, 0x0002, "US", samples) + element(0x0028, 0x0004, "CS", photometric) + ow(4, "abcd"));
    const auto implicitItem = [&](uint32_t paletteLength) {
        return item(implicitElement(0x0028, 0x0002, 2, samples) + implicitElement(0x0028, 0x0004, 12, photometric) + implicitElement(0x0028, 0x1201, paletteLength, "abcd"));
    };
    const auto elementOf = [](gdcm::VR vr, const std::string& bytes) {
        gdcm::DataElement de(gdcm::Tag(0x0088, 0x0200));
        de.SetVR(vr);
        de.SetByteValue(bytes.data(), gdcm::VL(uint32_t(bytes.size())));
        return de;
    };
    for (const gdcm::VR vr : {gdcm::VR(gdcm::VR::UN), gdcm::VR(gdcm::VR::INVALID)}) {
        const gdcm::DataElement de = elementOf(vr, implicitItem(4));
        std::string problem;
        const gdcm::SmartPointer<gdcm::SequenceOfItems> sq = detail::valueAsSequence(de, problem);
        EXPECT_EQ(problem, "");
        ASSERT_TRUE(sq);
        ASSERT_EQ(sq->GetNumberOfItems(), 1u);
        EXPECT_EQ(sq->GetItem(1).GetNestedDataSet().Size(), 3u);
    }
    // Explicit VR stored as UN (not CP-246's implicit VR): GDCM would go on
    // to byte-swapped and explicit readings; refused.
    std::string problem = detail::sequenceProblem(elementOf(gdcm::VR::UN, explicitItem));
    EXPECT_NE(problem.find("a sequence stored as 54 bytes (UN) that does not read as implicit VR little endian (DICOM CP-246)"), std::string::npos) << problem;
    // The palette data's length forged to 0xFB000000 bytes past its 4: refused.
    problem = detail::sequenceProblem(elementOf(gdcm::VR::UN, implicitItem(0xFB000000u)));
    EXPECT_NE(problem.find("that, read as implicit VR, declares 4211081216 bytes at its byte 42: GDCM would allocate them"), std::string::npos) << problem;
    // 16 bytes past: GDCM allocates 20 bytes and fails; in an implicit file
    // it then gives up on the bytes (let through), as UN it would try other
    // readings (refused).
    EXPECT_EQ(detail::sequenceProblem(elementOf(gdcm::VR::INVALID, implicitItem(20))), "");
    EXPECT_NE(detail::sequenceProblem(elementOf(gdcm::VR::UN, implicitItem(20))).find("CP-246"), std::string::npos);
}
