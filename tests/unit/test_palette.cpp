// Palette compression (Dado et al. §4.2) against a brute-force reference:
// every entry decodes and looks up to its input bytes; spatially coherent
// data compresses, unique values fall back to direct storage within 1% of
// the raw array; a corrupted serialisation is rejected.
#include <gtest/gtest.h>

#include <cstring>
#include <cmath>
#include <random>

#include <tbb/global_control.h>

#include "src/attributes/PaletteChannel.h"
#include "src/attributes/PaletteCompressor.h"
#include "src/util/Error.h"

using namespace vdbdag;

namespace {

std::vector<uint8_t> bytesOf(const std::vector<float>& v) {
    std::vector<uint8_t> b(v.size() * 4);
    std::memcpy(b.data(), v.data(), b.size());
    return b;
}

void expectExact(const std::vector<uint8_t>& input, uint32_t vs, const attributes::PaletteChannel& c) {
    ASSERT_EQ(c.entryCount, input.size() / vs);
    EXPECT_EQ(c.decodeAll(), input);
    std::vector<uint8_t> one(vs);
    std::mt19937 rng(3);
    for (int k = 0; k < 2000 && c.entryCount; ++k) {
        const uint64_t i = rng() % c.entryCount;
        c.lookup(i, one.data());
        ASSERT_EQ(std::memcmp(one.data(), &input[i * vs], vs), 0) << "entry " << i;
    }
    const auto back = attributes::deserializePalette(attributes::serializePalette(c), "test");
    EXPECT_EQ(back.decodeAll(), input);
}

} // namespace

TEST(Palette, CoherentFieldRoundTripsAndCompresses) {
    std::vector<float> v(300000);
    for (size_t i = 0; i < v.size(); ++i) v[i] = float(int(std::sin(double(i) * 1e-3) * 60)) / 60.0f + ((i / 3000) % 5 == 0 ? 1.0f : 0.0f);
    const auto input = bytesOf(v);
    const auto c = attributes::compressPalette(input, 4);
    expectExact(input, 4, c);
    EXPECT_LT(c.byteSize(), input.size() / 4) << "a field of ~120 values must need well under 8 bits per entry";
}

TEST(Palette, UniqueValuesStayWithinOnePercentOfRaw) {
    std::mt19937 rng(11);
    std::vector<float> v(200000);
    for (auto& x : v) { uint32_t bits = rng(); std::memcpy(&x, &bits, 4); }  // NaN payloads included
    const auto input = bytesOf(v);
    const auto c = attributes::compressPalette(input, 4);
    expectExact(input, 4, c);
    EXPECT_LE(double(c.byteSize()), double(input.size()) * 1.01);
}

TEST(Palette, ConstantAndMixedChannels) {
    const std::vector<float> constant(100000, -0.0f);
    const auto c = attributes::compressPalette(bytesOf(constant), 4);
    expectExact(bytesOf(constant), 4, c);
    EXPECT_LT(c.byteSize(), 1024u);
    // Runs of few values, then noise, then runs again; 12-byte and 24-byte values too.
    std::mt19937 rng(5);
    for (uint32_t vs : {1u, 8u, 12u, 24u}) {
        std::vector<uint8_t> mixed;
        for (int i = 0; i < 60000; ++i) {
            const int region = (i / 10000) % 3;
            for (uint32_t k = 0; k < vs; ++k) mixed.push_back(uint8_t(region == 1 ? rng() : (i / 700) % 3 + k));
        }
        expectExact(mixed, vs, attributes::compressPalette(mixed, vs));
    }
    expectExact({}, 4, attributes::compressPalette({}, 4));
}

TEST(Palette, CorruptedSerialisationIsRejected) {
    std::vector<float> v(5000);
    for (size_t i = 0; i < v.size(); ++i) v[i] = float(i % 37);
    const auto bytes = attributes::serializePalette(attributes::compressPalette(bytesOf(v), 4));
    for (size_t n = 0; n < bytes.size(); n += 7)
        EXPECT_THROW(attributes::deserializePalette(std::span<const uint8_t>(bytes.data(), n), "truncated"), Error) << n;
    auto bad = bytes;
    bad[4] ^= 0x40;  // entry count
    EXPECT_THROW(attributes::deserializePalette(bad, "corrupt"), Error);
}

TEST(Palette, OutputIsByteIdenticalForOneAndTwoThreads) {
    // Coherent plateaus plus noise: many phase-one blocks and many gaps for
    // the parallel phase two.
    std::vector<float> v(3'500'000);  // several 2^20-entry scan chunks
    std::mt19937 rng(11);
    for (size_t i = 0; i < v.size(); ++i)
        v[i] = float(int(std::sin(double(i) * 3e-4) * 300)) / 300.0f + ((i / 3000) % 5 == 0 ? float(rng() % 40) : 0.0f);
    const auto input = bytesOf(v);
    auto run = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        return attributes::serializePalette(attributes::compressPalette(input, 4));
    };
    const auto one = run(1), two = run(2);
    EXPECT_EQ(one, two);
    expectExact(input, 4, attributes::deserializePalette(two, "two threads"));
}

// A 0-bit block (every entry the one palette value) is checked once, not per
// entry: a forged 2^40-entry channel of a few dozen bytes is read at once
// (one check per entry would take hours), and its value is the material.
TEST(Palette, ZeroBitBlockOfHugeLengthIsCheckedOnce) {
    attributes::PaletteChannel c;
    c.valueSize = 4;
    c.entryCount = uint64_t(1) << 40;
    c.materials = {1, 2, 3, 4};
    attributes::PaletteBlock b;
    b.firstEntry = 0;
    b.dataOffset = 0;
    b.paletteOffset = attributes::PaletteBlock::kWholeMaterialArray;
    b.indexBits = 0;
    c.blocks.push_back(b);
    c.indexBits = {0, 0};
    const std::vector<uint8_t> bytes = attributes::serializePalette(c);
    EXPECT_LT(bytes.size(), 128u);
    const attributes::PaletteChannel back = attributes::deserializePalette(bytes, "forged");
    EXPECT_EQ(back.entryCount, uint64_t(1) << 40);
    // With no material the same block is refused.
    c.materials.clear();
    EXPECT_THROW(attributes::deserializePalette(attributes::serializePalette(c), "forged"), Error);
}

// The material array is in unsigned little-endian order (what makes its
// differences small), for every value size, and every size round-trips
// through the column layout, random values and many-valued blocks alike.
TEST(Palette, MaterialsAreSortedAndEveryValueSizeRoundTrips) {
    std::mt19937_64 rng(11);
    for (const uint32_t vs : {1u, 2u, 4u, 8u, 12u, 24u}) {
        std::vector<uint8_t> values(uint64_t(vs) * 20000);
        // 40 distinct values in runs, now and then another one: palettes pay even for bytes.
        std::vector<std::vector<uint8_t>> pool(40, std::vector<uint8_t>(vs));
        for (auto& p : pool)
            for (auto& b : p) b = uint8_t(rng());
        for (size_t i = 0; i < values.size() / vs; ++i) {
            const auto& p = pool[(i / 64 + (rng() % 50 == 0 ? rng() % 40 : 0)) % 40];
            std::memcpy(&values[i * vs], p.data(), vs);
        }
        const attributes::PaletteChannel c = attributes::compressPalette(values, vs);
        ASSERT_GT(c.materialCount(), 1u) << vs;
        for (uint64_t m = 1; m < c.materialCount(); ++m) {
            const uint8_t* a = &c.materials[(m - 1) * vs];
            const uint8_t* b = &c.materials[m * vs];
            int order = 0;
            for (uint32_t k = vs; k-- > 0 && order == 0;) order = a[k] < b[k] ? -1 : a[k] > b[k] ? 1 : 0;
            ASSERT_LT(order, 0) << "value size " << vs << ", material " << m;
        }
        expectExact(values, vs, c);
    }
}

// Files written before the column layout (FORMAT.md §7: no bit 31; plain
// palettes, the directory by rows) still read: the older layout written here
// by hand from the format's description.
TEST(Palette, TheOlderRowLayoutStillReads) {
    std::vector<float> v(5000);
    for (size_t i = 0; i < v.size(); ++i) v[i] = float(int(i / 13) % 40) * 0.25f;
    const std::vector<uint8_t> input = bytesOf(v);
    const attributes::PaletteChannel c = attributes::compressPalette(input, 4);
    std::vector<uint8_t> old;
    auto put = [&](const void* p, size_t n) { old.insert(old.end(), static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n); };
    auto planes = [](const std::vector<uint8_t>& bytes) {
        const size_t n = bytes.size() / 4;
        std::vector<uint8_t> out(bytes.size());
        for (size_t i = 0; i < n; ++i)
            for (size_t k = 0; k < 4; ++k) out[k * n + i] = bytes[i * 4 + k];
        return out;
    };
    const uint32_t vs = 4;
    put(&vs, 4);
    put(&c.entryCount, 8);
    uint64_t n = c.materials.size();
    put(&n, 8);
    const auto m = planes(c.materials);
    put(m.data(), m.size());
    n = c.palettes.size();
    put(&n, 8);
    put(c.palettes.data(), c.palettes.size() * 4);
    n = c.blocks.size();
    put(&n, 8);
    for (const auto& b : c.blocks) {
        put(&b.firstEntry, 8);
        put(&b.dataOffset, 8);
        put(&b.paletteOffset, 4);
        put(&b.indexBits, 1);
    }
    n = c.indexBits.size();
    put(&n, 8);
    put(c.indexBits.data(), c.indexBits.size() * 8);
    n = c.direct.size();
    put(&n, 8);
    const auto d = planes(c.direct);
    put(d.data(), d.size());
    EXPECT_EQ(attributes::deserializePalette(old, "old layout").decodeAll(), input);
}
