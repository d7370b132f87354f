// `vdbdag verify` of a scan (app/VerifyFile.h): the scan as `encode` reads
// it, every sample compared through OpenVDB's accessors with what the
// .ssvdag decodes to. Exit codes, the JSON report and the scratch folder,
// through the command line.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;
using vdbdag::testing::runCli;

namespace {

fs::path workDir() {
    const fs::path d = fs::temp_directory_path() / ("vdbdag_verify_scan_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

// A NRRD of 24x20x18 int16 samples (detached raw data) named STEM.nhdr.
fs::path writeScan(const std::string& stem, const std::vector<int16_t>& samples) {
    std::ofstream(workDir() / (stem + ".raw"), std::ios::binary).write(reinterpret_cast<const char*>(samples.data()), std::streamsize(samples.size() * 2));
    std::ofstream(workDir() / (stem + ".nhdr")) << "NRRD0004\ntype: int16\ndimension: 3\nsizes: 24 20 18\nendian: little\nencoding: raw\ndata file: " << stem
                                                << ".raw\n";
    return workDir() / (stem + ".nhdr");
}

bool isEmptyFolder(const fs::path& d) { return fs::is_empty(d); }

} // namespace

// A NRRD of int16 samples is identical after the round trip (exit 0), and
// the verify leaves nothing in its scratch folder; against the .ssvdag of
// the same scan with one sample changed it DIFFERS (exit 1), in exactly one
// value, and again leaves nothing; --volume 2 of a 3-D NRRD is refused in
// one line naming the scan (it was ignored), and a scan option on a .vdb is
// refused.
TEST(VerifyScan, AScanIsComparedAsEncodeReadsIt) {
    const size_t n = size_t(24) * 20 * 18;
    std::vector<int16_t> samples(n);
    std::mt19937 rng(3);
    for (size_t i = 0; i < n; ++i) samples[i] = int16_t(int(i % 301) - 150 + int(rng() % 7));
    const fs::path scan = writeScan("verified", samples);
    const fs::path scratch = workDir() / "scratch";
    fs::create_directories(scratch);
    auto r = runCli("verify " + scan.string() + " --scratch " + scratch.string());
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("identical after the round trip"), std::string::npos) << r.out;
    EXPECT_TRUE(isEmptyFolder(scratch));
    std::vector<int16_t> changed = samples;
    changed[n / 3] ^= 1;
    const fs::path other = workDir() / "changed.ssvdag";
    r = runCli("encode " + writeScan("changed", changed).string() + " -o " + other.string() + " --force");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = runCli("verify " + scan.string() + " --encoded " + other.string() + " --json --scratch " + scratch.string());
    EXPECT_EQ(r.exitCode, 1) << r.out << r.err;
    const nlohmann::json report = nlohmann::json::parse(r.out);
    EXPECT_FALSE(report["identical"].get<bool>());
    ASSERT_EQ(report["values"].size(), 1u) << r.out;
    EXPECT_EQ(report["values"][0]["active_values_differing"].get<uint64_t>(), 1u) << r.out;
    EXPECT_TRUE(isEmptyFolder(scratch));
    r = runCli("verify " + scan.string() + " --volume 2");  // a 3-D NRRD holds one volume (refused as NIfTI refuses it)
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("verified.nhdr: --volume 2 is out of range: the file holds 1 volume"), std::string::npos) << r.err;
    const fs::path vdb = workDir() / "decoded.vdb";
    ASSERT_EQ(runCli("decode " + other.string() + " -o " + vdb.string()).exitCode, 0);
    r = runCli("verify " + vdb.string() + " --volume 1");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("decoded.vdb"), std::string::npos) << r.err;
    fs::remove_all(workDir());
}
