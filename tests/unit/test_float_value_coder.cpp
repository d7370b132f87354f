// coding/FloatValueCoder (window coding 8) against its input and closed
// forms: a signed distance band of a sphere (computed here in double, the
// distance known in closed form) comes back bit for bit in well under half
// its 32 bits per voxel, under every mirror; every kind of float (NaN
// payloads, -0.0, infinities, subnormals, FLT_MAX, tiles) comes back bit for
// bit; half floats lose their 13 zero bits; the decoder gives the same bits
// with flush-to-zero and denormals-are-zero set (as a host application may
// leave them); corrupt payloads are refused without reading out of bounds;
// a vec3s window codes each component (coding 9); a thread's kept models
// code as a fresh thread's.
#include <gtest/gtest.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>
#include <thread>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <xmmintrin.h>
#endif

#include "src/attributes/PaletteCompressor.h"
#include "src/attributes/PredictedWindows.h"
#include "src/coding/FloatValueCoder.h"
#include "src/dag/Reflection.h"
#include "src/format/ZstdFrame.h"
#include "src/util/Error.h"
#include "tests/unit/PlacedBoxFixture.h"

namespace vdbdag::coding {
namespace {

struct FloatChannel {
    std::vector<uint64_t> layout;
    std::vector<BrickPlace> places;
    std::vector<uint32_t> bits;
};

// The voxels of a 32^3 box where `keep(X, Y, Z)`, as bricks in Morton order
// (empty ones left out), each with a mirror drawn from `rng`, entries at
// their stored bits, value `value(X, Y, Z)`.
template <typename Keep, typename Value>
FloatChannel sparseBox(std::mt19937& rng, Keep&& keep, Value&& value) {
    FloatChannel c;
    for (uint32_t m = 0; m < 512; ++m) {
        int bx = 0, by = 0, bz = 0;
        for (int k = 0; k < 3; ++k) bx |= int(m >> (3 * k) & 1) << k, by |= int(m >> (3 * k + 1) & 1) << k, bz |= int(m >> (3 * k + 2) & 1) << k;
        const uint32_t mirror = rng() % 8;
        uint64_t mask = 0;
        uint32_t brick[64];
        for (int z = 0; z < 4; ++z)
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 4; ++x) {
                    const int X = 4 * bx + x, Y = 4 * by + y, Z = 4 * bz + z;
                    if (!keep(X, Y, Z)) continue;
                    const unsigned bit = access::dagStoredBit(unsigned(x), unsigned(y), unsigned(z), mirror);
                    mask |= uint64_t(1) << bit;
                    brick[bit] = std::bit_cast<uint32_t>(value(X, Y, Z));
                }
        if (!mask) continue;
        c.layout.push_back(mask);
        c.places.push_back({4 * bx, 4 * by, 4 * bz, mirror});
        for (uint64_t b = mask; b; b &= b - 1) c.bits.push_back(brick[std::countr_zero(b)]);
    }
    return c;
}

// The narrow band (3 voxels each side) of a large sphere's signed distance
// in world units, voxel size h: its surface crosses the box near z = 15,
// bending by a voxel over the box (radius 205 voxels, a level set's scale).
FloatChannel sphereBand(uint32_t seed, double h = 0.01) {
    std::mt19937 rng(seed);
    const auto distance = [](int X, int Y, int Z) { return std::sqrt((X - 16.3) * (X - 16.3) + (Y - 15.1) * (Y - 15.1) + (Z + 189.7) * (Z + 189.7)) - 205.2; };
    return sparseBox(rng, [&](int X, int Y, int Z) { return std::fabs(distance(X, Y, Z)) < 3; },
                     [&](int X, int Y, int Z) { return float(distance(X, Y, Z) * h); });
}

std::vector<uint32_t> roundTrip(const FloatChannel& c, const std::vector<uint8_t>& payload) {
    std::vector<uint32_t> out(c.bits.size());
    decodePlacedFloats(payload, c.layout, c.places, out, "test");
    return out;
}

TEST(FloatValueCoder, ASignedDistanceBandComesBackBitForBitInUnderHalfItsBits) {
    for (const uint32_t seed : {1u, 2u, 3u}) {
        const FloatChannel c = sphereBand(seed);
        ASSERT_GT(c.bits.size(), 5000u);
        const std::vector<uint8_t> payload = encodePlacedFloats(c.bits, c.layout, c.places);
        EXPECT_EQ(roundTrip(c, payload), c.bits) << "seed " << seed;
        // A distance is linear along its gradient (here near z: 2P - PP),
        // so residuals are a few units of the value's last place, far under
        // its 24 significant bits.
        EXPECT_LT(payload.size() * 8, c.bits.size() * 16) << payload.size() << " bytes for " << c.bits.size() << " distances";
        // And far under the palettes of the same entries (all distinct).
        const std::vector<uint8_t> bytes(reinterpret_cast<const uint8_t*>(c.bits.data()), reinterpret_cast<const uint8_t*>(c.bits.data() + c.bits.size()));
        EXPECT_LT(payload.size() * 3 / 2, format::zstdFastSize(attributes::serializePalette(attributes::compressPalette(bytes, 4))));
    }
}

TEST(FloatValueCoder, EveryKindOfFloatComesBackBitForBit) {
    std::mt19937 rng(7);
    const uint32_t specials[] = {0x7FC01234u, 0xFFA00001u, 0x7F800000u, 0xFF800000u, 0x80000000u, 0x00000000u, 0x00000001u,
                                 0x807FFFFFu, 0x7F7FFFFFu, 0xFF7FFFFFu, 0x00800000u, 0x3F800000u, 0x7F800001u, 0xFFFFFFFFu};
    std::uniform_int_distribution<uint32_t> any;
    for (int variant = 0; variant < 3; ++variant) {
        auto c = testing::placedBox(rng, true, [&](int X, int Y, int Z) {
            const uint32_t r = rng() % 16;
            if (variant == 0 && r < 3) return int32_t(specials[rng() % std::size(specials)]);
            if (variant == 1) return int32_t(any(rng));  // pure noise
            if (variant == 2) return int32_t(std::bit_cast<uint32_t>(float(1e-39 * (X + Y - Z))));  // subnormals and their neighbours
            return int32_t(std::bit_cast<uint32_t>(float(std::sin(X * 0.3) * std::cos(Y * 0.2) + Z * 1e-3)));
        }, 7, 3, int32_t(0x7FC00000));
        std::vector<uint32_t> bits(c.entries.begin(), c.entries.end());
        FloatChannel f{c.layout, c.places, bits};
        EXPECT_EQ(roundTrip(f, encodePlacedFloats(f.bits, f.layout, f.places)), f.bits) << "variant " << variant;
    }
}

TEST(FloatValueCoder, HalfFloatsLoseTheirThirteenZeroBits) {
    FloatChannel c = sphereBand(4, 0.05);
    FloatChannel half = c;
    for (uint32_t& u : half.bits) u &= ~uint32_t(0x1FFF);  // 10 mantissa bits, as a half holds
    const std::vector<uint8_t> payload = encodePlacedFloats(half.bits, half.layout, half.places);
    ASSERT_GE(payload.size(), 2u);
    EXPECT_EQ(payload[1], 13) << "the common zero low bits";
    EXPECT_EQ(roundTrip(half, payload), half.bits);
    EXPECT_LT(payload.size() * 2, encodePlacedFloats(c.bits, c.layout, c.places).size()) << "13 bits fewer per voxel";
}

#if defined(__x86_64__) || defined(__i386__)
TEST(FloatValueCoder, TheSameBitsWithFlushToZeroAndDenormalsAreZero) {
    std::mt19937 rng(9);
    // Tiny values: predictions and errors land in and around the subnormals.
    FloatChannel c = sparseBox(rng, [](int X, int Y, int Z) { return (X + 2 * Y + 3 * Z) % 5 != 0; },
                               [](int X, int Y, int Z) { return float(1e-38 * std::sin(X * 0.4 + Y * 0.3) + 3e-39 * Z); });
    const std::vector<uint8_t> plain = encodePlacedFloats(c.bits, c.layout, c.places);
    const unsigned csr = _mm_getcsr();
    _mm_setcsr(csr | 0x8040u);  // FTZ | DAZ
    const std::vector<uint8_t> flushed = encodePlacedFloats(c.bits, c.layout, c.places);
    std::vector<uint32_t> back(c.bits.size());
    decodePlacedFloats(plain, c.layout, c.places, back, "test");
    _mm_setcsr(csr);
    EXPECT_EQ(flushed, plain);
    EXPECT_EQ(back, c.bits);
}
#endif

TEST(FloatValueCoder, CorruptPayloadsAreRefused) {
    const FloatChannel c = sphereBand(5);
    const std::vector<uint8_t> good = encodePlacedFloats(c.bits, c.layout, c.places);
    std::vector<uint32_t> out(c.bits.size());
    EXPECT_THROW(decodePlacedFloats(std::span(good).first(good.size() / 2), c.layout, c.places, out, "half"), Error);
    EXPECT_THROW(decodePlacedFloats(std::span(good).first(1), c.layout, c.places, out, "header"), Error);
    std::vector<uint8_t> bad = good;
    bad[0] = 1;
    EXPECT_THROW(decodePlacedFloats(bad, c.layout, c.places, out, "generation"), Error);
    bad = good;
    bad[1] = 32;
    EXPECT_THROW(decodePlacedFloats(bad, c.layout, c.places, out, "shift"), Error);
    bad = good;
    bad.insert(bad.end(), 64, 0x5A);
    EXPECT_THROW(decodePlacedFloats(bad, c.layout, c.places, out, "trailing"), Error);
    std::vector<uint32_t> fewer(c.bits.size() - 1);
    EXPECT_THROW(decodePlacedFloats(good, c.layout, c.places, fewer, "entries"), Error);
    // Random flips decode to garbage or a refusal, inside the buffer (ASan).
    std::mt19937 rng(11);
    for (int i = 0; i < 50; ++i) {
        bad = good;
        bad[2 + rng() % (bad.size() - 2)] ^= uint8_t(1u << (rng() % 8));
        try {
            decodePlacedFloats(bad, c.layout, c.places, out, "flipped");
        } catch (const Error&) {
        }
    }
}

// Each thread keeps its models from one window to the next (ThreadLease.h):
// a window codes as on a fresh thread, whatever the thread coded before (a
// noisy window, vectors, a decode that a cut payload stopped half way).
TEST(FloatValueCoder, AWindowCodesAsOnAFreshThreadWhateverTheThreadCodedBefore) {
    const FloatChannel c = sphereBand(8);
    std::vector<uint8_t> fresh;
    std::thread([&] { fresh = encodePlacedFloats(c.bits, c.layout, c.places); }).join();
    std::mt19937 rng(13);
    FloatChannel noise = c;
    for (uint32_t& u : noise.bits) u = uint32_t(rng());
    const std::vector<uint8_t> noisy = encodePlacedFloats(noise.bits, noise.layout, noise.places);
    std::vector<uint32_t> out(c.bits.size());
    EXPECT_THROW(decodePlacedFloats(std::span(noisy).first(noisy.size() / 2), c.layout, c.places, out, "cut"), Error);
    std::vector<uint32_t> vectors(3 * c.bits.size());
    for (uint32_t& u : vectors) u = std::bit_cast<uint32_t>(float(rng() % 1000) * 0.25f);
    encodePlacedFloatVectors(vectors, c.layout, c.places);
    EXPECT_EQ(encodePlacedFloats(c.bits, c.layout, c.places), fresh);
    EXPECT_EQ(roundTrip(c, fresh), c.bits);
}

// Through the predicted windows: a float channel's window is coding 8 and
// reads back bit for bit.
TEST(FloatValueCoder, AFloatWindowIsStoredAsCodingEight) {
    const FloatChannel c = sphereBand(6);
    const std::vector<uint8_t> bytes(reinterpret_cast<const uint8_t*>(c.bits.data()), reinterpret_cast<const uint8_t*>(c.bits.data() + c.bits.size()));
    const std::vector<uint8_t> windows = attributes::encodePredictedWindows(bytes, 4, c.layout, c.places, attributes::FloatChannel{});
    const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(windows, 4, c.layout, "test");
    ASSERT_EQ(dir.windows.size(), 1u);
    EXPECT_EQ(attributes::windowRawBytes(windows, dir.windows[0], "test").at(0), attributes::detail::kFloatCoding);
    EXPECT_EQ(attributes::decodePredictedWindows(windows, 4, c.layout, "test", c.places), bytes);
    // What `info` reports: one window of coding 8, read from its first byte.
    std::vector<uint64_t> expected(attributes::detail::kCodingCount);
    expected[attributes::detail::kFloatCoding] = 1;
    EXPECT_EQ(attributes::predictedWindowCodings(windows, 4, c.layout, "test"), expected);
    EXPECT_STREQ(attributes::predictedCodingName(attributes::detail::kFloatCoding), "predicted floats");
}

// A vec3s window (a velocity field: the gradient of the sphere's distance,
// a unit vector per voxel, in closed form) is coding 9, each component
// predicted on its own: bit for bit back, under two thirds of the palettes' bytes;
// a component cut short is refused.
TEST(FloatValueCoder, AVectorWindowCodesEachComponent) {
    std::mt19937 rng(12);
    std::vector<uint8_t> bytes;
    FloatChannel where = sparseBox(rng, [](int X, int Y, int Z) { return (X * 7 + Y * 3 + Z) % 11 != 0; }, [](int, int, int) { return 0.0f; });
    // Re-walk the same bricks to give each entry its vector (stored-bit order within each brick).
    for (size_t b = 0; b < where.layout.size(); ++b) {
        const BrickPlace& pl = where.places[b];
        float brick[64][3];
        for (int z = 0; z < 4; ++z)
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 4; ++x) {
                    const double X = pl.x + x - 40.3, Y = pl.y + y - 11.9, Z = pl.z + z + 25.2, r = std::sqrt(X * X + Y * Y + Z * Z);
                    float* v = brick[access::dagStoredBit(unsigned(x), unsigned(y), unsigned(z), pl.mirror)];
                    v[0] = float(X / r), v[1] = float(Y / r), v[2] = float(Z / r);
                }
        for (uint64_t m = where.layout[b]; m; m &= m - 1) {
            const auto* p = reinterpret_cast<const uint8_t*>(brick[std::countr_zero(m)]);
            bytes.insert(bytes.end(), p, p + 12);
        }
    }
    ASSERT_EQ(bytes.size(), where.bits.size() * 12);
    const std::vector<uint8_t> windows = attributes::encodePredictedWindows(bytes, 12, where.layout, where.places, attributes::FloatChannel{});
    const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(windows, 12, where.layout, "test");
    ASSERT_EQ(dir.windows.size(), 1u);
    const std::vector<uint8_t> raw = attributes::windowRawBytes(windows, dir.windows[0], "test");
    EXPECT_EQ(raw.at(0), attributes::detail::kFloatVectorCoding);
    EXPECT_EQ(attributes::decodePredictedWindows(windows, 12, where.layout, "test", where.places), bytes);
    EXPECT_LT(windows.size() * 3 / 2, format::zstdFastSize(attributes::serializePalette(attributes::compressPalette(bytes, 12))));
    const std::span<const uint8_t> body = std::span<const uint8_t>(raw).subspan(1);
    EXPECT_THROW(attributes::decodeFloatVectors(body.first(body.size() / 2), where.layout, where.bits.size(), where.places, "cut"), Error);
    EXPECT_THROW(attributes::decodeFloatVectors(body.first(4), where.layout, where.bits.size(), where.places, "count"), Error);
}

} // namespace
} // namespace vdbdag::coding
