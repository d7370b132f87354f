// The element walk that guards GDCM (vdb_bridge/detail/DicomElementWalk.h)
// on files that start like no DICOM: GDCM parses them as a data set all the
// same, and Debian's GDCM asserts (aborts) where an element is cut off after
// its tag. In-process, so that an abort ends the test rather than passing
// as a refusal. Needs no ../shared data.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "src/util/Error.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/DicomSeries.h"
#include "vdb_bridge/detail/DicomElementWalk.h"

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

// Found by fuzz_scan_headers (issue 38; the input is
// tests/fuzz/regressions/scan_headers/dicom_cut_after_tag_abort, which also
// holds an element without a VR, refused first since): no preamble, a first
// element of group 0000 (so the file starts like no DICOM), a CT's header
// elements, then 5 bytes: a tag and one byte of a VR. GDCM aborted in
// VR16ExplicitDataElement::ReadPreValue (gdcmVR16ExplicitDataElement.txx:146);
// the walk now refuses the cut-off element whatever the file starts with, so
// the scan skips the file as not DICOM, saying why.
TEST(DicomWalk, AnElementCutOffAfterItsTagIsRefusedWhateverTheFileStartsWith) {
    std::string bytes = std::string("\0\0\0\0OB\0\0\x02\0\0\0\0\x01", 14);
    bytes += element(0x0002, 0x0010, "UI", std::string("1.2.840.10008.1.2.\0", 18));
    bytes += element(0x0008, 0x0016, "UI", std::string("1.2.840.10008.5.1.4.1.1.2\0", 26));
    bytes += element(0x0008, 0x0060, "CS", "CT");
    bytes += element(0x0028, 0x0010, "US", std::string("\xff\xff", 2));
    bytes += std::string("\x28\0\x10\0\0", 5);  // a tag and one byte
    const fs::path file = write("cut.dcm", bytes);
    const std::string problem = detail::elementLengthProblem(file.string(), true);
    EXPECT_EQ(problem.rfind("not a DICOM file (no DICM preamble", 0), 0u) << problem;
    EXPECT_NE(problem.find("the file ends inside an element (its last 5 bytes"), std::string::npos) << problem;
    const DicomScan scan = scanDicom(file.parent_path().string());
    EXPECT_TRUE(scan.series.empty());
    ASSERT_EQ(scan.skipped.size(), 1u);
    EXPECT_NE(scan.skipped[0].find("not a DICOM file"), std::string::npos) << scan.skipped[0];
    // The same file without its last 5 bytes walks to its end, and GDCM
    // reads it (its Rows alone make no image: skipped, saying so).
    fs::remove(file);
    const fs::path whole = write("whole.dcm", bytes.substr(0, bytes.size() - 5));
    EXPECT_EQ(detail::elementLengthProblem(whole.string(), true), "");
    const DicomScan again = scanDicom(whole.parent_path().string());
    ASSERT_EQ(again.skipped.size(), 1u);
    EXPECT_EQ(again.skipped[0].find("not a DICOM file"), std::string::npos) << again.skipped[0];
    fs::remove_all(file.parent_path());
}

// The DICOM inputs fuzz_scan_headers failed on (tests/fuzz/regressions,
// format byte 4; its README says what each did): each is refused by the
// walk before GDCM parses it, and `vdbdag info` of the file and of its
// folder, under a 1.5 GB address-space cap, lists it as skipped. GDCM aborted on two; for dicom_element_without_vr_oom `info`
// took 1.7 GB (GDCM guessed how to read an element whose VR bytes are no
// VR and allocated the length it read, where the walk had read it as
// implicit).
TEST(DicomWalk, TheFuzzRegressionsAreRefusedBeforeGdcmAndCostNothing) {
    const fs::path dir = fs::path(VDBDAG_SOURCE_DIR) / "tests/fuzz/regressions/scan_headers";
    const std::pair<const char*, const char*> cases[] = {{"dicom_cut_after_tag_abort", "element (0028,0000) at byte 278 has no valid VR"},
                                                         {"dicom_element_without_vr_oom", "has no valid VR under an explicit transfer syntax"},
                                                         {"dicom_open_pixel_data_abort", "the file ends inside a sequence or item (at byte 8 of 8)"}};
    for (const auto& [name, why] : cases) {
        std::ifstream in(dir / name, std::ios::binary);
        const std::string input((std::istreambuf_iterator<char>(in)), {});
        ASSERT_GT(input.size(), 1u) << name;
        ASSERT_EQ(input[0], '\4') << name << ": a DICOM input";
        const fs::path file = write(std::string(name) + ".dcm", input.substr(1));
        const std::string problem = detail::elementLengthProblem(file.string());  // the whole file, as a lone file's DICOMDIR check reads it
        EXPECT_EQ(problem.rfind("not a DICOM file", 0), 0u) << name << ": " << problem;
        EXPECT_NE(problem.find(why), std::string::npos) << name << ": " << problem;
        // The file alone (the fuzz target's call) and its folder: skipped,
        // saying why (the folder's scan stops its walk at the pixel data,
        // so the third is skipped there as no image).
        for (const fs::path& input : {file, file.parent_path()}) {
            const auto r = vdbdag::testing::runShell("ulimit -v 1500000; " + std::string(VDBDAG_BINARY) + " info " + quote(input) + " --json");
            ASSERT_EQ(r.exitCode, 0) << name << ": " << r.err;
            const nlohmann::json info = nlohmann::json::parse(r.out);
            EXPECT_EQ(info["series"].size(), 0u) << name;
            ASSERT_EQ(info["skipped"].size(), 1u) << name;
            EXPECT_EQ(info["skipped"][0].get<std::string>().rfind(file.string() + ": ", 0), 0u) << info["skipped"][0];
        }
        fs::remove_all(file.parent_path());
    }
}
