// A 4-D scan's volumes coded with the volume before as their reference
// (pipeline/SeriesReference.h, window codings 21 and 22, section
// ValueReference: docs/FORMAT.md 8.6). Every sample is compared with the
// samples the test wrote (not with another decode of ours), through the
// public reader library grid by grid in any order (each grid read alone
// reads its chain back to its key grid), and the forged files a reader
// must refuse are refused in one line.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "include/vdbdag/vdbdag.h"
#include "src/attributes/PredictedWindows.h"
#include "src/encoding/AttributeLayout.h"
#include "src/format/SsvdagContainer.h"
#include "src/format/SsvdagFile.h"
#include "src/util/Error.h"
#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;
using vdbdag::testing::runCli;

namespace {

constexpr int kNx = 40, kNy = 36, kNz = 20, kVolumes = 11;
constexpr size_t kPerVolume = size_t(kNx) * kNy * kNz;

fs::path workDir() {
    const fs::path d = fs::temp_directory_path() / ("vdbdag_series_reference_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

// A series whose volumes share a smooth anatomy and drift slowly, each
// with noise of its own (an fMRI's character): sample (x, y, z, t).
std::vector<float> seriesSamples() {
    std::vector<float> s(kPerVolume * kVolumes);
    std::mt19937 rng(7);
    std::vector<int> anatomy(kPerVolume);
    for (size_t i = 0; i < kPerVolume; ++i) {
        const int x = int(i % kNx), y = int(i / kNx % kNy), z = int(i / (size_t(kNx) * kNy));
        anatomy[i] = 600 + 4 * ((x * 7 + y * 3) % 97) + 9 * z + int(rng() % 200);  // texture a slice does not predict
    }
    for (int t = 0; t < kVolumes; ++t)
        for (size_t i = 0; i < kPerVolume; ++i) s[size_t(t) * kPerVolume + i] = float(anatomy[i] + t + int(rng() % 9) - 4);
    return s;
}

// The series as a 4-D NRRD of `type` (int16: coding 19's walk; float: the
// integers of a float scan, coding 20's), detached raw data.
fs::path writeSeries(const std::string& stem, const std::vector<float>& samples, bool floats) {
    std::ofstream raw(workDir() / (stem + ".raw"), std::ios::binary);
    for (const float v : samples) {
        if (floats) raw.write(reinterpret_cast<const char*>(&v), 4);
        else {
            const int16_t s = int16_t(v);
            raw.write(reinterpret_cast<const char*>(&s), 2);
        }
    }
    std::ofstream(workDir() / (stem + ".nhdr")) << "NRRD0004\ntype: " << (floats ? "float" : "int16") << "\ndimension: 4\nsizes: " << kNx << " " << kNy
                                                << " " << kNz << " " << kVolumes << "\nspace directions: (1,0,0) (0,1,0) (0,0,1) none\nendian: little\nencoding: raw\ndata file: "
                                                << stem << ".raw\n";
    return workDir() / (stem + ".nhdr");
}

// Grid t's samples through the public reader, as floats.
std::vector<float> readVolume(const vdbdag::File& file, int t, bool floats) {
    const vdbdag::Grid& g = file.grid(size_t(t));
    const vdbdag::IndexBBox box{{0, 0, 0}, {kNx - 1, kNy - 1, kNz - 1}};
    std::vector<float> out(kPerVolume);
    if (floats) {
        g.sampleBox(box, 1, out.data());
    } else {
        std::vector<int32_t> ints(kPerVolume);
        g.sampleBox(box, 1, ints.data());
        for (size_t i = 0; i < kPerVolume; ++i) out[i] = float(ints[i]);
    }
    return out;
}

std::vector<uint8_t> fileBytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

} // namespace

// int16 and float32-of-integers series: with the default key grids (every
// 8) the file is smaller than every volume coded alone (--key-every 1) by
// at least a fifth, its container is version 3, and grids 1-7 and 9-10
// carry ValueReference sections while the key grids 0 and 8 do not; every
// sample of every grid read alone, last first, is the sample written.
TEST(SeriesReference, EachVolumeTakesTheOneBeforeAndReadsBackAlone) {
    const std::vector<float> samples = seriesSamples();
    for (const bool floats : {false, true}) {
        SCOPED_TRACE(floats ? "float32" : "int16");
        const std::string stem = floats ? "floats" : "ints";
        const fs::path scan = writeSeries(stem, samples, floats);
        const fs::path keyed = workDir() / (stem + ".ssvdag"), alone = workDir() / (stem + "_alone.ssvdag");
        auto r = runCli("encode " + scan.string() + " -o " + keyed.string() + " --force --json");
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const nlohmann::json report = nlohmann::json::parse(r.out);
        ASSERT_TRUE(report.contains("series_reference")) << r.out;
        EXPECT_EQ(report["series_reference"]["referenced_grids"].get<uint64_t>(), 9u) << r.out;
        ASSERT_EQ(runCli("encode " + scan.string() + " -o " + alone.string() + " --force --key-every 1").exitCode, 0);
        const uint64_t keyedBytes = fs::file_size(keyed), aloneBytes = fs::file_size(alone);
        EXPECT_LT(double(keyedBytes), 0.8 * double(aloneBytes)) << keyedBytes << " against " << aloneBytes;
        const std::vector<uint8_t> bytes = fileBytes(keyed);
        uint32_t version = 0;
        std::memcpy(&version, bytes.data() + 8, 4);
        EXPECT_EQ(version, 3u);
        std::vector<int> referencing;
        for (const auto& s : vdbdag::format::readContainer(bytes, keyed.string()))
            if (s.kind == vdbdag::format::SectionKind::ValueReference) referencing.push_back(int(s.grid));
        EXPECT_EQ(referencing, (std::vector<int>{1, 2, 3, 4, 5, 6, 7, 9, 10}));
        const vdbdag::File file = vdbdag::File::open(keyed.string());
        ASSERT_EQ(file.gridCount(), size_t(kVolumes));
        EXPECT_EQ(file.formatVersion(), 3u);
        for (const int t : {10, 7, 3, 8, 0, 1, 2, 4, 5, 6, 9}) {
            const std::vector<float> got = readVolume(file, t, floats);
            EXPECT_EQ(std::memcmp(got.data(), samples.data() + size_t(t) * kPerVolume, kPerVolume * 4), 0) << "volume " << t;
        }
        // format::readSceneFile of one grid reads its chain (grids 8 and 9:
        // the key grid 8 first) and gives grid 9 alone, its values those of
        // the whole file's read (which the decode below checks sample for sample).
        {
            vdbdag::format::ReadOptions one;
            one.grid = 9;
            const vdbdag::format::SsvdagScene alone9 = vdbdag::format::readSceneFile(keyed.string(), one);
            const vdbdag::format::SsvdagScene all = vdbdag::format::readSceneFile(keyed.string());
            ASSERT_EQ(alone9.grids.size(), 1u);
            EXPECT_EQ(alone9.grids[0].record.name, all.grids[9].record.name);
            EXPECT_EQ(alone9.grids[0].active.attributes.size(), kPerVolume * 4);
            EXPECT_EQ(alone9.grids[0].active.attributes, all.grids[9].active.attributes);
        }
        // A decode of the whole file (each grid's reference decoded whole
        // before it) gives the same: the .nhdr written back, every sample.
        const fs::path back = workDir() / (stem + "_back.nhdr");
        r = runCli("decode " + keyed.string() + " -o " + back.string() + " --force");
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const fs::path rawBack = workDir() / (stem + "_back.raw");
        ASSERT_TRUE(fs::exists(rawBack));
        {
            const std::vector<uint8_t> raw = fileBytes(rawBack);
            ASSERT_EQ(raw.size(), samples.size() * (floats ? 4 : 2));
            for (size_t i = 0; i < samples.size(); i += 997) {
                float v;
                if (floats) std::memcpy(&v, raw.data() + 4 * i, 4);
                else {
                    int16_t s;
                    std::memcpy(&s, raw.data() + 2 * i, 2);
                    v = float(s);
                }
                EXPECT_EQ(v, samples[i]) << "sample " << i;
            }
        }
    }
    fs::remove_all(workDir());
}

// What a reader refuses, each in one line naming the file: a referenced
// window whose grid names no reference (its ValueReference dropped), a
// reference past the first grid or to the grid itself (also on grid 0;
// the reader library too, on open), a reference to a grid whose DAG
// differs; and a chain longer than kMaxReferenceChain.
TEST(SeriesReference, ForgedReferencesAreRefused) {
    namespace format = vdbdag::format;
    const fs::path scan = writeSeries("forged", seriesSamples(), false);
    const fs::path good = workDir() / "forged.ssvdag";
    ASSERT_EQ(runCli("encode " + scan.string() + " -o " + good.string() + " --force").exitCode, 0);
    const std::vector<format::Section> sections = format::readContainer(fileBytes(good), good.string());
    const auto refuse = [&](std::vector<format::Section> forged, const std::string& expected) {
        const std::vector<uint8_t> bytes = format::writeContainer(forged);
        try {
            (void)format::readScene(bytes, "forged.ssvdag");
            ADD_FAILURE() << "read, expected: " << expected;
        } catch (const vdbdag::Error& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(expected), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            EXPECT_EQ(what.rfind("forged.ssvdag", 0), 0u) << what;
        }
    };
    const auto distance = [](uint32_t d) {
        std::vector<uint8_t> b(4);
        std::memcpy(b.data(), &d, 4);
        return b;
    };
    {  // grid 2's ValueReference dropped
        std::vector<format::Section> forged;
        for (const auto& s : sections)
            if (!(s.kind == format::SectionKind::ValueReference && s.grid == 2)) forged.push_back(s);
        refuse(forged, "is coded with a series' reference, and its layer names none");
    }
    for (const uint32_t d : {0u, 3u}) {  // grid 2 naming itself, or grid -1
        std::vector<format::Section> forged = sections;
        for (auto& s : forged)
            if (s.kind == format::SectionKind::ValueReference && s.grid == 2) s.data = distance(d);
        refuse(forged, d == 0 ? "names the grid itself" : "not an earlier grid of this read");
        // The reader library, which opens a file by its headers, refuses it too, on open.
        const fs::path file = workDir() / "forged_reference.ssvdag";
        const std::vector<uint8_t> bytes = format::writeContainer(forged);
        std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        try {
            (void)vdbdag::File::open(file.string());
            ADD_FAILURE() << "opened a file whose grid 2 takes its reference from grid " << int(2 - int(d));
        } catch (const vdbdag::Error& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(d == 0 ? "names the grid itself" : "not an earlier grid of its frame"), std::string::npos) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        }
    }
    {  // grid 1's reference made grid 0 with another DAG: grid 0's DAG sections taken from a one-volume scan
        const fs::path other = workDir() / "other.nhdr";
        std::vector<int16_t> small(size_t(kNx) * kNy * 4, 5);
        std::ofstream(workDir() / "other.raw", std::ios::binary).write(reinterpret_cast<const char*>(small.data()), std::streamsize(small.size() * 2));
        std::ofstream(other) << "NRRD0004\ntype: int16\ndimension: 3\nsizes: " << kNx << " " << kNy << " 4\nendian: little\nencoding: raw\ndata file: other.raw\n";
        const fs::path otherFile = workDir() / "other.ssvdag";
        ASSERT_EQ(runCli("encode " + other.string() + " -o " + otherFile.string() + " --force").exitCode, 0);
        std::vector<format::Section> forged;
        for (const auto& s : sections)
            if (s.grid != 0 || s.kind == format::SectionKind::FileInfo) forged.push_back(s);
        for (const auto& s : format::readContainer(fileBytes(otherFile), "other"))
            if (s.grid == 0 && s.kind != format::SectionKind::FileInfo && s.kind != format::SectionKind::FileMetadata) forged.push_back(s);
        refuse(forged, "whose active voxels or values are not this grid's kind");
    }
    {  // a ValueReference on grid 0
        std::vector<format::Section> forged = sections;
        forged.push_back({format::SectionKind::ValueReference, 0, distance(1)});
        refuse(forged, "names grid -1, not an earlier grid of this read");
    }
    // A chain of 256 grids: the reader stops at kMaxReferenceChain.
    {
        const std::vector<uint8_t> payload(100, 0);
        std::shared_ptr<const vdbdag::attributes::WindowReference> chain;
        const std::vector<uint64_t> layout;
        EXPECT_THROW(
            {
                for (unsigned i = 0; i <= vdbdag::attributes::kMaxReferenceChain; ++i)
                    chain = std::make_shared<const vdbdag::attributes::WindowReference>(
                        vdbdag::attributes::encodePredictedWindows({}, 4, layout), 4, layout, chain, "chain");
            },
            vdbdag::Error);
        ASSERT_TRUE(chain);
        EXPECT_EQ(chain->depth, vdbdag::attributes::kMaxReferenceChain);
    }
    fs::remove_all(workDir());
}
