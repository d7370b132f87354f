// The .ssvdag container and atomic output: round trips (raw and zstd), the
// documented byte layout, and the reader against truncated, corrupted and
// forged files: every prefix and every single-byte change must give
// vdbdag::Error (never a crash, a hang or a huge allocation), forged tables
// with valid checksums must be caught by the bounds and size checks before
// anything is allocated. Reading and writing whole files:
// test_atomic_file.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <cstdlib>
#include <cstring>
#include <new>
#include <random>
#include <thread>
#include <sstream>

#include <xxhash.h>

#include "src/format/ByteIO.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "tests/unit/AllocationProbe.h"

using namespace vdbdag;
using format::Section;
using format::SectionKind;
using test::AllocationProbe;

namespace {

// Container options that store every section as it is.
format::ContainerOptions raw() {
    format::ContainerOptions o;
    o.compress = false;
    return o;
}

// Layout constants as documented in SsvdagContainer.cpp.
constexpr size_t kHeader = 16, kEntry = 48;
constexpr size_t kKindAt = 0, kCodecAt = 8, kReservedAt = 12, kOffsetAt = 16, kStoredAt = 24, kRawAt = 32, kSumAt = 40;

template <typename T>
T load(const std::vector<uint8_t>& b, size_t at) {
    T v;
    std::memcpy(&v, b.data() + at, sizeof(T));
    return v;
}
template <typename T>
void store(std::vector<uint8_t>& b, size_t at, T v) {
    std::memcpy(b.data() + at, &v, sizeof(T));
}
size_t entryAt(size_t i) { return kHeader + i * kEntry; }
uint32_t sectionCount(const std::vector<uint8_t>& b) { return load<uint32_t>(b, 12); }

// Recomputes every in-bounds payload checksum and the table checksum, so a
// forged table passes the checksums and only the structural checks remain.
void fixChecksums(std::vector<uint8_t>& b) {
    const size_t tableEnd = kHeader + sectionCount(b) * kEntry;
    for (size_t i = 0; i < sectionCount(b); ++i) {
        const uint64_t offset = load<uint64_t>(b, entryAt(i) + kOffsetAt), stored = load<uint64_t>(b, entryAt(i) + kStoredAt);
        if (offset <= b.size() && stored <= b.size() - offset) store<uint64_t>(b, entryAt(i) + kSumAt, XXH3_64bits(b.data() + offset, stored));
    }
    store<uint64_t>(b, tableEnd, XXH3_64bits(b.data(), tableEnd));
}

std::string errorOf(std::span<const uint8_t> bytes, const std::string& name = "forged.ssvdag") {
    try {
        format::readContainer(bytes, name);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

std::vector<uint8_t> noise(size_t n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<uint8_t> v(n);
    for (auto& b : v) b = uint8_t(rng());
    return v;
}

std::vector<Section> mixedSections() {
    std::vector<uint8_t> text;
    for (int i = 0; i < 300; ++i) text.push_back(uint8_t("symmetry-aware "[i % 15]));
    return {
        {SectionKind::FileInfo, 0, {}},
        {SectionKind::DagInner, 0, text},
        {SectionKind::DagLeaves, 0, noise(150, 1)},
        {SectionKind::GridInfo, 1, {1, 2, 3, 4, 5}},
        {SectionKind(77), 2, std::vector<uint8_t>(100, 0)},  // unknown kinds are kept
    };
}

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

void expectSame(const std::vector<Section>& a, const std::vector<Section>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].kind, b[i].kind) << i;
        EXPECT_EQ(a[i].grid, b[i].grid) << i;
        EXPECT_TRUE(a[i].data == b[i].data) << "section " << i << " payload differs";
    }
}

} // namespace

// ---- round trips and layout -------------------------------------------------

TEST(Container, RoundTripsRawAndCompressed) {
    std::vector<uint8_t> big;  // 3 MB, compressible
    for (size_t i = 0; i < (size_t(3) << 20); ++i) big.push_back(uint8_t((i * 7) % 251 < 128 ? i & 15 : 0));
    const std::vector<uint8_t> random = noise(64 << 10, 2);
    const std::vector<std::vector<Section>> cases = {
        {},
        {{SectionKind::FileInfo, 0, {}}},
        {{SectionKind::DagInner, 3, big}, {SectionKind::DagLeaves, 1, random}, {SectionKind::Values, 7, {42}}},
        mixedSections(),
    };
    for (const auto& sections : cases) {
        for (bool compress : {true, false}) {
            format::ContainerOptions options;
            options.compress = compress;
            const auto bytes = format::writeContainer(sections, options);
            expectSame(format::readContainer(bytes, "mem"), sections);
            const auto summary = format::summarizeContainer(bytes, "mem");
            ASSERT_EQ(summary.size(), sections.size());
            uint64_t stored = 0;
            for (size_t i = 0; i < summary.size(); ++i) {
                EXPECT_EQ(summary[i].kind, sections[i].kind);
                EXPECT_EQ(summary[i].grid, sections[i].grid);
                EXPECT_EQ(summary[i].rawBytes, sections[i].data.size());
                if (!summary[i].compressed) EXPECT_EQ(summary[i].storedBytes, summary[i].rawBytes);
                else EXPECT_LT(summary[i].storedBytes, summary[i].rawBytes) << "zstd kept although it does not shrink";
                if (!compress) { EXPECT_FALSE(summary[i].compressed); }
                if (compress && sections[i].data == big) { EXPECT_LT(summary[i].storedBytes, big.size() / 20); }
                if (sections[i].data == random) { EXPECT_FALSE(summary[i].compressed) << "random data should stay raw"; }
                stored += summary[i].storedBytes;
            }
            EXPECT_EQ(bytes.size(), kHeader + kEntry * sections.size() + 8 + stored) << "payloads are back to back";
        }
    }
}

TEST(Container, LargeSectionsUseTheThreadedPathAndRoundTrip) {
    std::vector<uint8_t> large(size_t(6) << 20);
    for (size_t i = 0; i < large.size(); ++i) large[i] = uint8_t((i >> 10) * 31);
    const std::vector<Section> sections{{SectionKind::Values, 0, large}};
    const auto bytes = format::writeContainer(sections);
    EXPECT_LT(bytes.size(), large.size() / 50);
    expectSame(format::readContainer(bytes, "mem"), sections);
}

// ContainerOptions::parallel: the sections compressed side by side (here
// each on its own thread, started last first) give the bytes of one after
// another, in memory and streamed (each section released as it goes), a
// section on zstd's own threaded path (over 4 MiB) among them.
TEST(Container, SectionsCompressedSideBySideGiveTheBytesOfOneAfterAnother) {
    std::vector<uint8_t> large(size_t(6) << 20);
    for (size_t i = 0; i < large.size(); ++i) large[i] = uint8_t((i >> 10) * 31 + (i % 7 == 0 ? i : 0));
    std::vector<Section> sections = mixedSections();
    sections.push_back({SectionKind::Values, 1, large});
    sections.push_back({SectionKind::InactiveInner, 1, noise(64 << 10, 5)});
    sections.push_back({SectionKind::DagInner, 2, std::vector<uint8_t>(large.begin(), large.begin() + (1 << 20))});
    format::ContainerOptions threads;
    std::atomic<int> calls{0};
    threads.parallel = [&](size_t n, const std::function<void(size_t)>& body) {
        std::vector<std::thread> pool;
        for (size_t k = n; k-- > 0;) pool.emplace_back([&body, k] { body(k); });
        for (std::thread& t : pool) t.join();
        ++calls;
    };
    const std::vector<uint8_t> serial = format::writeContainer(sections);
    EXPECT_EQ(format::writeContainer(sections, threads), serial);
    std::ostringstream streamed;
    std::vector<Section> released = sections;
    format::writeContainerTo(std::move(released), streamed, threads);
    const std::string s = streamed.str();
    EXPECT_EQ(std::vector<uint8_t>(s.begin(), s.end()), serial);
    EXPECT_EQ(calls.load(), 2);
    expectSame(format::readContainer(serial, "mem"), sections);
}

TEST(Container, ByteLayoutIsAsDocumented) {
    const auto sections = mixedSections();
    const auto bytes = format::writeContainer(sections);
    const uint8_t magic[8] = {0x89, 'S', 'S', 'V', 'D', 'A', 'G', '\n'};
    ASSERT_GE(bytes.size(), 24u);
    EXPECT_EQ(std::memcmp(bytes.data(), magic, 8), 0);
    EXPECT_EQ(load<uint32_t>(bytes, 8), 1u);
    ASSERT_EQ(sectionCount(bytes), sections.size());
    const size_t tableEnd = kHeader + kEntry * sections.size();
    EXPECT_EQ(load<uint64_t>(bytes, tableEnd), XXH3_64bits(bytes.data(), tableEnd));
    uint64_t next = tableEnd + 8;
    for (size_t i = 0; i < sections.size(); ++i) {
        const size_t e = entryAt(i);
        EXPECT_EQ(load<uint32_t>(bytes, e + kKindAt), uint32_t(sections[i].kind));
        EXPECT_EQ(load<uint32_t>(bytes, e + 4), sections[i].grid);
        const uint32_t codec = load<uint32_t>(bytes, e + kCodecAt);
        EXPECT_TRUE(codec == 0 || codec == 1);
        EXPECT_EQ(load<uint32_t>(bytes, e + kReservedAt), 0u);
        EXPECT_EQ(load<uint64_t>(bytes, e + kOffsetAt), next);
        const uint64_t stored = load<uint64_t>(bytes, e + kStoredAt);
        EXPECT_EQ(load<uint64_t>(bytes, e + kRawAt), sections[i].data.size());
        EXPECT_EQ(load<uint64_t>(bytes, e + kSumAt), XXH3_64bits(bytes.data() + next, stored));
        if (codec == 0 && stored) { EXPECT_EQ(std::memcmp(bytes.data() + next, sections[i].data.data(), stored), 0); }
        next += stored;
    }
    EXPECT_EQ(next, bytes.size());
    // The 300-byte repetitive section is zstd, the 150 random bytes raw.
    EXPECT_EQ(load<uint32_t>(bytes, entryAt(1) + kCodecAt), 1u);
    EXPECT_EQ(load<uint32_t>(bytes, entryAt(2) + kCodecAt), 0u);
}

TEST(Container, SectionKindNames) {
    EXPECT_STREQ(format::sectionKindName(SectionKind::GridInfo), "GridInfo");
    EXPECT_STREQ(format::sectionKindName(SectionKind::DagInner), "DagInner");
    EXPECT_STREQ(format::sectionKindName(SectionKind::ValueErrors), "ValueErrors");
    EXPECT_STREQ(format::sectionKindName(SectionKind(1000)), "unknown");
}

// ---- truncation and corruption ------------------------------------------------

TEST(Container, EveryPrefixIsATruncationError) {
    for (bool compress : {true, false}) {
        format::ContainerOptions options;
        options.compress = compress;
        for (const auto& sections : {std::vector<Section>{}, mixedSections()}) {
            const auto bytes = format::writeContainer(sections, options);
            ASSERT_NO_THROW(format::readContainer(bytes, "full"));
            for (size_t n = 0; n < bytes.size(); ++n) {
                const std::span<const uint8_t> prefix(bytes.data(), n);
                const std::string m = errorOf(prefix, "cut.ssvdag");
                EXPECT_EQ(m.rfind("cut.ssvdag: truncated", 0), 0u) << "prefix of " << n << " bytes: " << m;
                EXPECT_THROW(format::summarizeContainer(prefix, "cut"), Error) << n;
            }
        }
    }
}

TEST(Container, TruncationMessageSaysWhere) {
    const auto bytes = format::writeContainer(mixedSections(), raw());
    const size_t cut = bytes.size() - 50;  // inside section 4 (100 raw bytes)
    EXPECT_EQ(errorOf(std::span<const uint8_t>(bytes.data(), cut), "file.ssvdag"),
              "file.ssvdag: truncated: section 4 (kind 77 of grid 2) ends at byte " + std::to_string(bytes.size()) + " but the file has " +
                  std::to_string(cut) + " bytes");
}

TEST(Container, EverySingleByteCorruptionIsAnError) {
    for (bool compress : {true, false}) {
        format::ContainerOptions options;
        options.compress = compress;
        const auto bytes = format::writeContainer(mixedSections(), options);
        for (size_t i = 0; i < bytes.size(); ++i) {
            for (uint8_t flip : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
                auto bad = bytes;
                bad[i] ^= flip;
                EXPECT_THROW(format::readContainer(bad, "corrupt"), Error) << "byte " << i << " xor " << int(flip);
            }
        }
    }
}

TEST(Container, PayloadCorruptionNamesTheSection) {
    auto bytes = format::writeContainer(mixedSections());
    const uint64_t offset = load<uint64_t>(bytes, entryAt(1) + kOffsetAt);
    bytes[offset + 3] ^= 0x10;
    EXPECT_EQ(errorOf(bytes, "file.ssvdag"), "file.ssvdag: section 1 ('DagInner' of grid 0): checksum mismatch, the file is corrupted");
    auto table = format::writeContainer(mixedSections());
    table[entryAt(2) + 4] ^= 1;  // the grid index of section 2
    EXPECT_EQ(errorOf(table, "file.ssvdag"), "file.ssvdag: checksum mismatch in the header or section table: the file is corrupted");
}

// Whatever a forger writes into a zstd payload (with the checksums fixed up),
// the reader either refuses it with Error or returns exactly the raw size.
TEST(Container, ForgedZstdPayloadsNeverBreakTheReader) {
    const auto bytes = format::writeContainer(mixedSections());
    ASSERT_EQ(load<uint32_t>(bytes, entryAt(1) + kCodecAt), 1u);
    const uint64_t offset = load<uint64_t>(bytes, entryAt(1) + kOffsetAt), stored = load<uint64_t>(bytes, entryAt(1) + kStoredAt);
    size_t refused = 0;
    for (uint64_t i = offset; i < offset + stored; ++i) {
        for (uint8_t flip : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xFF)}) {
            auto bad = bytes;
            bad[i] ^= flip;
            fixChecksums(bad);
            try {
                const auto sections = format::readContainer(bad, "forged");
                ASSERT_EQ(sections.size(), 5u);
                EXPECT_EQ(sections[1].data.size(), 300u);
            } catch (const Error&) {
                ++refused;
            }
        }
    }
    EXPECT_GT(refused, 0u);
}

TEST(Container, SceneEveryTruncationIsAnError) {
    for (bool compress : {true, false}) {
        const auto bytes = smallSceneBytes(compress);
        ASSERT_NO_THROW(format::readScene(bytes, "full"));
        for (size_t n = 0; n < bytes.size(); ++n) {
            std::span<const uint8_t> prefix(bytes.data(), n);
            EXPECT_THROW(format::readScene(prefix, "truncated"), Error) << "prefix of " << n << " bytes";
        }
    }
}

TEST(Container, SceneEverySingleByteCorruptionIsAnError) {
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

// ---- forged tables (valid checksums) ---------------------------------------------

TEST(Container, ForgedHugeRawSizeIsRejectedBeforeAllocating) {
    const std::vector<Section> sections{{SectionKind::DagInner, 0, std::vector<uint8_t>(1000, 1)}};
    auto bytes = format::writeContainer(sections);
    ASSERT_EQ(load<uint32_t>(bytes, entryAt(0) + kCodecAt), 1u);
    const uint64_t stored = load<uint64_t>(bytes, entryAt(0) + kStoredAt);
    for (uint64_t raw : {uint64_t(1) << 50, stored * 65536 + 4097, ~uint64_t(0)}) {
        auto bad = bytes;
        store<uint64_t>(bad, entryAt(0) + kRawAt, raw);
        fixChecksums(bad);
        AllocationProbe probe;
        const std::string m = errorOf(bad);
        EXPECT_NE(m.find("which zstd cannot produce"), std::string::npos) << m;
        EXPECT_LT(probe.largest(), size_t(1) << 20) << "allocated " << probe.largest() << " bytes for a forged size";
        EXPECT_THROW(format::summarizeContainer(bad, "forged"), Error);
    }
    // Within the plausible bound but not what the frame declares: still
    // rejected before the claimed size is allocated.
    auto bad = bytes;
    store<uint64_t>(bad, entryAt(0) + kRawAt, stored * 65536);
    fixChecksums(bad);
    AllocationProbe probe;
    const std::string m = errorOf(bad);
    EXPECT_NE(m.find("the zstd frame declares 1000 bytes"), std::string::npos) << m;
    EXPECT_LT(probe.largest(), size_t(1) << 20) << "allocated " << probe.largest() << " bytes for a forged size";
}

TEST(Container, ForgedRawCodecSizesAreRejected) {
    auto bytes = format::writeContainer({{SectionKind::DagLeaves, 0, noise(100, 3)}}, raw());
    store<uint64_t>(bytes, entryAt(0) + kRawAt, 101);
    fixChecksums(bytes);
    EXPECT_NE(errorOf(bytes).find("claims 101 raw bytes for 100 bytes stored uncompressed"), std::string::npos) << errorOf(bytes);
}

TEST(Container, OverlapsGapsAndOutOfBoundsOffsetsAreRejected) {
    const auto good = format::writeContainer(mixedSections(), raw());
    const uint64_t off1 = load<uint64_t>(good, entryAt(1) + kOffsetAt);
    const uint64_t off2 = load<uint64_t>(good, entryAt(2) + kOffsetAt);
    struct Case {
        std::function<void(std::vector<uint8_t>&)> forge;
        std::string expect;
    };
    const std::vector<Case> cases = {
        {[&](auto& b) { store<uint64_t>(b, entryAt(2) + kOffsetAt, off1); }, "overlaps section 1"},
        {[&](auto& b) { store<uint64_t>(b, entryAt(2) + kOffsetAt, off2 - 1); }, "overlaps section 1"},
        {[&](auto& b) { store<uint64_t>(b, entryAt(2) + kOffsetAt, off2 + 1); }, "unaccounted bytes"},
        {[&](auto& b) { store<uint64_t>(b, entryAt(1) + kOffsetAt, 0); }, "inside the header and table"},
        {[&](auto& b) { store<uint64_t>(b, entryAt(3) + kOffsetAt, ~uint64_t(0) - 2); }, "truncated: section 3"},
        {[&](auto& b) { store<uint64_t>(b, entryAt(3) + kStoredAt, ~uint64_t(0) - 2); }, "impossible size"},
        {[&](auto& b) { store<uint64_t>(b, entryAt(3) + kStoredAt, uint64_t(1) << 40); }, "truncated: section 3"},
        {[&](auto& b) { store<uint32_t>(b, entryAt(0) + kCodecAt, 2); }, "unknown codec 2"},
        {[&](auto& b) { store<uint32_t>(b, entryAt(0) + kReservedAt, 1); }, "non-zero reserved field"},
        {[&](auto& b) { b.push_back(0); }, "1 unexpected bytes after the last section"},
        {[&](auto& b) { store<uint32_t>(b, 12, 0xFFFFFFFFu); }, "truncated: the table of 4294967295 sections"},
        {[&](auto& b) { store<uint32_t>(b, 8, 7); }, "unsupported format version 7 (this vdbdag reads versions 1 to 3)"},
    };
    for (const Case& c : cases) {
        auto bad = good;
        c.forge(bad);
        if (sectionCount(bad) == sectionCount(good)) fixChecksums(bad);
        AllocationProbe probe;
        const std::string m = errorOf(bad, "forged.ssvdag");
        EXPECT_NE(m.find(c.expect), std::string::npos) << m;
        EXPECT_EQ(m.rfind("forged.ssvdag: ", 0), 0u) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        EXPECT_LT(probe.largest(), size_t(1) << 20);
        EXPECT_THROW(format::summarizeContainer(bad, "forged"), Error) << c.expect;
    }
}

TEST(Container, ZstdFramesMustMatchTheTableExactly) {
    const auto good = format::writeContainer(mixedSections());
    ASSERT_EQ(load<uint32_t>(good, entryAt(1) + kCodecAt), 1u);
    // One byte more or less than the frame declares.
    for (uint64_t raw : {299u, 301u}) {
        auto bad = good;
        store<uint64_t>(bad, entryAt(1) + kRawAt, raw);
        fixChecksums(bad);
        EXPECT_NE(errorOf(bad).find("the zstd frame declares 300 bytes but the table " + std::to_string(raw)), std::string::npos) << errorOf(bad);
    }
    // Extra bytes after the frame inside the section: rebuild a file whose
    // section 1 is the frame plus a second (empty) frame's worth of junk.
    const std::vector<Section> one{{SectionKind::DagInner, 0, std::vector<uint8_t>(500, 9)}};
    auto bytes = format::writeContainer(one);
    const std::vector<uint8_t> junk{0x28, 0xB5, 0x2F, 0xFD, 0x20, 0x00, 0x01, 0x00, 0x00};  // an empty zstd frame
    bytes.insert(bytes.end(), junk.begin(), junk.end());
    store<uint64_t>(bytes, entryAt(0) + kStoredAt, load<uint64_t>(bytes, entryAt(0) + kStoredAt) + junk.size());
    fixChecksums(bytes);
    EXPECT_NE(errorOf(bytes).find("the zstd frame takes"), std::string::npos) << errorOf(bytes);
}

TEST(Container, NotAnSsvdagFile) {
    const std::string text = "this is a text file, not an ssvdag\n";
    const std::vector<uint8_t> bytes(text.begin(), text.end());
    EXPECT_EQ(errorOf(bytes, "a.txt"), "a.txt: not an .ssvdag file (bad magic)");
    auto crlf = format::writeContainer({});
    crlf.insert(crlf.begin() + 7, '\r');  // a text-mode copy turned the LF into CRLF
    EXPECT_NE(errorOf(crlf, "c.ssvdag").find("line endings"), std::string::npos) << errorOf(crlf, "c.ssvdag");
    // The inputs of `encode` given to a command that reads .ssvdag files: named, with the command that takes them
    // (issue 38: "bad magic" for a .nvdb or a scan).
    auto named = [&](std::vector<uint8_t> head, size_t at, const std::string& magic, const std::string& expect) {
        head.resize(std::max(head.size(), at + magic.size() + 8), 0);
        std::memcpy(head.data() + at, magic.data(), magic.size());
        const std::string e = errorOf(head, "in.x");
        EXPECT_NE(e.find("not an .ssvdag file: it is " + expect), std::string::npos) << e;
        EXPECT_NE(e.find("vdbdag encode in.x -o OUT.ssvdag"), std::string::npos) << e;
    };
    named({}, 0, std::string("\x20\x42\x44\x56\0\0\0\0", 8), "an OpenVDB .vdb file");
    named({}, 0, "NanoVDB0", "a NanoVDB file");
    named({}, 0, "NRRD0004\n", "a NRRD file");
    named(std::vector<uint8_t>(352, 0), 344, "n+1", "a NIfTI file");
    named(std::vector<uint8_t>(200, 0), 128, "DICM", "a DICOM file");
    // A raw volume has no magic: by its name.
    const std::vector<uint8_t> samples(64, 7);
    const std::string e = errorOf(samples, "ct_4x4x4_uint8.raw");
    EXPECT_NE(e.find("not an .ssvdag file: it is a raw volume"), std::string::npos) << e;
    EXPECT_NE(e.find("vdbdag encode ct_4x4x4_uint8.raw -o OUT.ssvdag"), std::string::npos) << e;
}

// A forged root origin (checksums recomputed, as a hostile writer would) is
// refused when the file is read, before any coordinate arithmetic: the
// fuzzers found 9223372036854775801 + 8 overflowing in the DAG walk.
TEST(Container, ForgedRootOriginOutsideInt32IsRejected) {
    const auto bytes = smallSceneBytes(false);
    std::vector<Section> sections = format::readContainer(bytes, "small");
    for (const int64_t forged : {int64_t(9223372036854775801), int64_t(1) << 31, -(int64_t(1) << 31) - 1}) {
        std::vector<Section> copy = sections;
        bool changed = false;
        for (Section& s : copy)
            if (s.kind == SectionKind::DagLevels) {
                std::memcpy(s.data.data(), &forged, sizeof forged);  // i64 origin x comes first
                changed = true;
            }
        ASSERT_TRUE(changed);
        const auto forgedBytes = format::writeContainer(copy, raw());
        try {
            format::readScene(forgedBytes, "forged");
            ADD_FAILURE() << "origin " << forged << " accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("int32 index range"), std::string::npos) << e.what();
        }
    }
    // An origin off the 4-aligned brick grid would put a brick's voxels past
    // the end of an OpenVDB leaf (found reading the reader for docs/FORMAT.md).
    for (const int64_t forged : {int64_t(5), int64_t(2), int64_t(-3), (int64_t(1) << 31) - 1}) {
        std::vector<Section> copy = sections;
        for (Section& s : copy)
            if (s.kind == SectionKind::DagLevels) std::memcpy(s.data.data(), &forged, sizeof forged);
        try {
            format::readScene(format::writeContainer(copy, raw()), "forged");
            ADD_FAILURE() << "origin " << forged << " accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("not a multiple of 4"), std::string::npos) << e.what();
        }
    }
    // The extremes of the range itself (on the brick grid) are valid origins;
    // at the upper one this scene's voxels reach past INT32_MAX, which the
    // read refuses by the voxels' bounds (issue 38 #10), not by the origin.
    for (const int64_t edge : {-(int64_t(1) << 31), (int64_t(1) << 31) - 4}) {
        std::vector<Section> copy = sections;
        for (Section& s : copy)
            if (s.kind == SectionKind::DagLevels) std::memcpy(s.data.data(), &edge, sizeof edge);
        if (edge < 0) {
            EXPECT_NO_THROW(format::readScene(format::writeContainer(copy, raw()), "edge")) << edge;
            continue;
        }
        try {
            format::readScene(format::writeContainer(copy, raw()), "edge");
            ADD_FAILURE() << "voxels past INT32_MAX accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("reaches voxel index"), std::string::npos) << e.what();
        }
    }
}

// A section of a kind the scene reader does not know is checked but never
// inflated, whatever it claims to hold (a forged file carried a real 2 GiB
// zstd frame there). The allocation probe shows the difference.
TEST(Container, SceneReaderNeverInflatesUnknownSections) {
    std::vector<Section> sections = format::readContainer(smallSceneBytes(true), "small");
    sections.push_back({SectionKind(77), 0, std::vector<uint8_t>(size_t(16) << 20, 0)});  // 16 MiB of zeros: a small zstd frame
    const auto bytes = format::writeContainer(sections);
    ASSERT_LT(bytes.size(), size_t(1) << 20);
    {
        AllocationProbe probe;
        EXPECT_NO_THROW(format::readScene(bytes, "unknown-kind"));
        EXPECT_LT(probe.largest(), size_t(1) << 20) << "the unknown section was inflated";
    }
    {
        AllocationProbe probe;  // the generic container reader keeps it: the probe sees it
        EXPECT_EQ(format::readContainer(bytes, "unknown-kind").back().data.size(), size_t(16) << 20);
        EXPECT_GE(probe.largest(), size_t(16) << 20);
    }
    // Corruption of the skipped section is still caught by its checksum.
    auto bad = bytes;
    const size_t last = sectionCount(bad) - 1;
    bad[load<uint64_t>(bad, entryAt(last) + kOffsetAt)] ^= 1;
    EXPECT_THROW(format::readScene(bad, "corrupt"), Error);
}
