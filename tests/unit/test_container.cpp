// The .ssvdag reader against truncated, corrupted and forged files: every
// prefix and every single-byte change of a real file must give vdbdag::Error
// (never a crash, a hang or a huge allocation); atomic writes leave nothing
// behind on failure.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <xxhash.h>

#include "src/format/ByteIO.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/AtomicFile.h"
#include "src/util/Error.h"

namespace fs = std::filesystem;
using namespace vdbdag;

namespace {

std::vector<uint8_t> smallSceneBytes(bool compress) {
    GridRecord record;
    record.name = "small";
    record.gridClass = "level set";
    record.vdbDescriptor = {9, 8, 7, 6};
    for (int i = 0; i < 40; ++i) record.topology.bricks.push_back({4 * (i % 5), 4 * (i / 5), -8, uint64_t(0x8421) * uint64_t(i + 1)});
    record.topology.tiles.push_back({64, 64, 64, 3});
    format::SsvdagScene scene;
    scene.grids.push_back(pipeline::encodeGrid(record));
    format::ContainerOptions options;
    options.compress = compress;
    return format::writeScene(scene, options);
}

} // namespace

TEST(Container, SectionsRoundTripRawAndCompressed) {
    std::mt19937_64 rng(5);
    std::vector<format::Section> sections;
    sections.push_back({format::SectionKind::FileInfo, 0, {}});
    sections.push_back({format::SectionKind::DagInner, 3, std::vector<uint8_t>(100000, 7)});
    std::vector<uint8_t> noise(5000);
    for (auto& b : noise) b = uint8_t(rng());
    sections.push_back({format::SectionKind::DagLeaves, 1, noise});
    for (bool compress : {true, false}) {
        format::ContainerOptions options;
        options.compress = compress;
        const auto bytes = format::writeContainer(sections, options);
        const auto back = format::readContainer(bytes, "mem");
        ASSERT_EQ(back.size(), sections.size());
        for (size_t i = 0; i < back.size(); ++i) {
            EXPECT_EQ(back[i].kind, sections[i].kind);
            EXPECT_EQ(back[i].grid, sections[i].grid);
            EXPECT_EQ(back[i].data, sections[i].data);
        }
        if (compress) EXPECT_LT(bytes.size(), 20000u);
    }
}

TEST(Container, EveryTruncationIsAnError) {
    for (bool compress : {true, false}) {
        const auto bytes = smallSceneBytes(compress);
        ASSERT_NO_THROW(format::readScene(bytes, "full"));
        for (size_t n = 0; n < bytes.size(); ++n) {
            std::span<const uint8_t> prefix(bytes.data(), n);
            EXPECT_THROW(format::readScene(prefix, "truncated"), Error) << "prefix of " << n << " bytes";
        }
    }
}

TEST(Container, EverySingleByteCorruptionIsAnError) {
    for (bool compress : {true, false}) {
        const auto bytes = smallSceneBytes(compress);
        for (size_t i = 0; i < bytes.size(); ++i) {
            for (uint8_t flip : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
                auto bad = bytes;
                bad[i] ^= flip;
                EXPECT_THROW(format::readScene(bad, "corrupt"), Error) << "byte " << i << " xor " << int(flip);
            }
        }
    }
}

TEST(Container, ForgedHugeRawSizeIsRejectedBeforeAllocating) {
    // Rebuild a valid table that claims 2^50 raw bytes for a tiny zstd payload,
    // with correct checksums, so only the plausibility check can stop it.
    std::vector<format::Section> sections{{format::SectionKind::DagInner, 0, std::vector<uint8_t>(1000, 1)}};
    auto bytes = format::writeContainer(sections);
    const size_t rawSizeAt = 16 + 32;  // entry: kind, grid, codec, reserved, offset, stored, raw
    uint64_t huge = uint64_t(1) << 50;
    std::memcpy(bytes.data() + rawSizeAt, &huge, 8);
    const uint64_t tableEnd = 16 + 48;
    const uint64_t sum = XXH3_64bits(bytes.data(), tableEnd);
    std::memcpy(bytes.data() + tableEnd, &sum, 8);
    try {
        format::readContainer(bytes, "forged");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cannot produce"), std::string::npos) << e.what();
    }
}

TEST(Container, ErrorsAreOneLineAndNameTheSource) {
    const auto bytes = smallSceneBytes(true);
    std::vector<uint8_t> bad(bytes.begin(), bytes.begin() + long(bytes.size() / 2));
    try {
        format::readScene(bad, "half.ssvdag");
        FAIL();
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.rfind("half.ssvdag: ", 0), 0u) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos);
    }
    EXPECT_THROW(format::readFileBytes("/nonexistent/file.ssvdag"), Error);
}

TEST(AtomicFile, ReplacesAtomicallyAndLeavesNothingOnFailure) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_atomic_" + std::to_string(getpid()));
    fs::create_directories(dir);
    const fs::path target = dir / "out.bin";
    const std::vector<uint8_t> a(10, 1), b(20, 2);
    writeFileAtomically(target.string(), a);
    writeFileAtomically(target.string(), b);
    EXPECT_EQ(fs::file_size(target), 20u);
    EXPECT_THROW(writeViaTemporary((dir / "never.vdb").string(), [](const std::string& tmp) {
                     std::ofstream(tmp) << "partial";
                     throw Error("writer failed");
                 }),
                 Error);
    EXPECT_THROW(writeFileAtomically((dir / "missing" / "x.bin").string(), a), Error);
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(dir)) { (void)e; ++files; }
    EXPECT_EQ(files, 1u) << "a temporary or partial file was left behind";
    fs::remove_all(dir);
}
