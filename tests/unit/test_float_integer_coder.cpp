// coding/FloatIntegerCoder (window coding 12) against its input: every kind
// of float (NaN payloads, -0.0, infinities, subnormals, negatives, tiles)
// comes back bit for bit under every mirror; half floats are coded without
// their 13 zero bits (the payload says 13); a window of +-0 alone (31 zero
// bits) comes back; corrupt headers and streams are refused without reading
// out of bounds. Through the predicted windows: a half-float fog window is
// stored as coding 12 when its first bricks code smaller so, and a
// full-precision one never is; both read back bit for bit.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "src/attributes/PredictedWindows.h"
#include "src/coding/FloatIntegerCoder.h"
#include "src/coding/FloatValueCoder.h"
#include "src/util/Error.h"
#include "tests/unit/PlacedBoxFixture.h"

namespace vdbdag::coding {
namespace {

struct Window {
    std::vector<uint64_t> layout;
    std::vector<BrickPlace> places;
    std::vector<uint32_t> bits;
};

// A dense 32^3 box (testing::placedBox: mirrored bricks, every 7th brick a
// tile) of the float bits `value(X, Y, Z)` gives.
template <typename Value>
Window box(uint32_t seed, Value&& value) {
    std::mt19937 rng(seed);
    const auto c = testing::placedBox(rng, true, [&](int X, int Y, int Z) { return int32_t(value(X, Y, Z, rng)); }, 7, 3, int32_t(0x3F800000));
    return {c.layout, c.places, std::vector<uint32_t>(c.entries.begin(), c.entries.end())};
}

std::vector<uint32_t> roundTrip(const Window& w, const std::vector<uint8_t>& payload) {
    std::vector<uint32_t> out(w.bits.size());
    decodePlacedFloatIntegers(payload, w.layout, w.places, out, "test");
    return out;
}

// A smoke-like density saved as half floats: a smooth field with
// turbulence (noise of a fiftieth of its swing, the same at a voxel however
// it is reached), positive, its low 13 mantissa bits zero.
uint32_t halfDensity(int X, int Y, int Z) {
    std::mt19937 at(uint32_t(X) * 73856093u ^ uint32_t(Y) * 19349663u ^ uint32_t(Z) * 83492791u);
    const double noise = std::normal_distribution<double>(0.0, 0.02)(at);
    const double d = 0.6 + 0.5 * std::sin(X * 0.21 + Y * 0.07) * std::cos(Z * 0.17 - Y * 0.05) + 0.002 * X + noise;
    return std::bit_cast<uint32_t>(float(std::max(d, 1e-5))) & ~uint32_t(0x1FFF);
}

TEST(FloatIntegerCoder, EveryKindOfFloatComesBackBitForBit) {
    const uint32_t specials[] = {0x7FC01234u, 0xFFA00001u, 0x7F800000u, 0xFF800000u, 0x80000000u, 0x00000000u, 0x00000001u,
                                 0x807FFFFFu, 0x7F7FFFFFu, 0xFF7FFFFFu, 0x00800000u, 0x3F800000u, 0x7F800001u, 0xFFFFFFFFu};
    for (int variant = 0; variant < 4; ++variant) {
        const Window w = box(uint32_t(variant), [&](int X, int Y, int Z, std::mt19937& rng) -> uint32_t {
            if (variant == 0 && rng() % 16 < 3) return specials[rng() % std::size(specials)];
            if (variant == 1) return uint32_t(rng());  // pure noise: every bit pattern
            if (variant == 2) return std::bit_cast<uint32_t>(float(1e-39 * (X + Y - Z)));  // subnormals, both signs
            return std::bit_cast<uint32_t>(float(std::sin(X * 0.3) * std::cos(Y * 0.2) - Z * 1e-3));  // both signs
        });
        EXPECT_EQ(roundTrip(w, encodePlacedFloatIntegers(w.bits, w.layout, w.places)), w.bits) << "variant " << variant;
    }
}

TEST(FloatIntegerCoder, HalfFloatsAreCodedWithoutTheirThirteenZeroBits) {
    const Window w = box(5, [](int X, int Y, int Z, std::mt19937&) { return halfDensity(X, Y, Z); });
    const std::vector<uint8_t> payload = encodePlacedFloatIntegers(w.bits, w.layout, w.places);
    ASSERT_GE(payload.size(), 10u);
    EXPECT_EQ(payload[1], 13) << "the common zero low bits";
    EXPECT_EQ(roundTrip(w, payload), w.bits);
    // Of 32 bits per entry, the 13 zero ones cost nothing, nor does most of
    // the other 19 (the noise's own bits remain).
    EXPECT_LT(payload.size() * 8, w.bits.size() * 10) << payload.size() << " bytes for " << w.bits.size() << " entries";
    // Only zeros, of both signs: 31 zero bits, integers 0 and -1.
    Window z = box(6, [](int, int, int, std::mt19937&) { return 0u; });
    for (size_t i = 0; i < z.bits.size(); ++i) z.bits[i] = i % 3 ? 0u : 0x80000000u;  // the tiles' entries too
    const std::vector<uint8_t> zp = encodePlacedFloatIntegers(z.bits, z.layout, z.places);
    EXPECT_EQ(zp.at(1), 31);
    EXPECT_EQ(roundTrip(z, zp), z.bits);
}

TEST(FloatIntegerCoder, CorruptPayloadsAreRefused) {
    const Window w = box(7, [](int X, int Y, int Z, std::mt19937&) { return halfDensity(X, Y, Z); });
    const std::vector<uint8_t> good = encodePlacedFloatIntegers(w.bits, w.layout, w.places);
    std::vector<uint32_t> out(w.bits.size());
    EXPECT_THROW(decodePlacedFloatIntegers(std::span(good).first(9), w.layout, w.places, out, "header"), Error);
    EXPECT_THROW(decodePlacedFloatIntegers(std::span(good).first(good.size() / 2), w.layout, w.places, out, "half"), Error);
    std::vector<uint8_t> bad = good;
    bad[0] = 3;  // generations 0-2 are read
    EXPECT_THROW(decodePlacedFloatIntegers(bad, w.layout, w.places, out, "generation"), Error);
    bad = good;
    bad[1] = 32;
    EXPECT_THROW(decodePlacedFloatIntegers(bad, w.layout, w.places, out, "shift"), Error);
    bad = good;
    bad[9] = 0x7F;  // max = 2^31 - 1 + ...: beyond 19-bit magnitudes under a shift of 13
    EXPECT_THROW(decodePlacedFloatIntegers(bad, w.layout, w.places, out, "range"), Error);
    bad = good;
    std::swap_ranges(bad.begin() + 2, bad.begin() + 6, bad.begin() + 6);  // min > max
    EXPECT_THROW(decodePlacedFloatIntegers(bad, w.layout, w.places, out, "order"), Error);
    // Random flips decode to garbage or a refusal, inside the buffer (ASan);
    // whatever decodes maps back to floats without overflow (UBSan).
    std::mt19937 rng(11);
    for (int i = 0; i < 50; ++i) {
        bad = good;
        bad[10 + rng() % (bad.size() - 10)] ^= uint8_t(1u << (rng() % 8));
        try {
            decodePlacedFloatIntegers(bad, w.layout, w.places, out, "flipped");
        } catch (const Error&) {
        }
    }
}

// Through the predicted windows (attributes/PredictedWindowWriter.cpp).
TEST(FloatIntegerCoder, AHalfFloatFogWindowIsStoredAsCodingTwelveAndAFullOneNever) {
    const auto windowOf = [](const Window& w) {
        const std::vector<uint8_t> bytes(reinterpret_cast<const uint8_t*>(w.bits.data()), reinterpret_cast<const uint8_t*>(w.bits.data() + w.bits.size()));
        const std::vector<uint8_t> windows = attributes::encodePredictedWindows(bytes, 4, w.layout, w.places, attributes::FloatChannel{});
        const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(windows, 4, w.layout, "test");
        EXPECT_EQ(attributes::decodePredictedWindows(windows, 4, w.layout, "test", w.places), bytes);
        return attributes::windowRawBytes(windows, dir.windows.at(0), "test").at(0);
    };
    const Window half = box(8, [](int X, int Y, int Z, std::mt19937&) { return halfDensity(X, Y, Z); });
    // The writer's choice agrees with the two codings' sizes on the whole window.
    const bool integersSmaller = encodePlacedFloatIntegers(half.bits, half.layout, half.places).size() < encodePlacedFloats(half.bits, half.layout, half.places).size();
    EXPECT_TRUE(integersSmaller);
    EXPECT_EQ(windowOf(half), integersSmaller ? attributes::detail::kFloatIntegerCoding : attributes::detail::kFloatCoding);
    const Window full = box(9, [](int X, int Y, int Z, std::mt19937&) { return std::bit_cast<uint32_t>(float(0.6 + 0.5 * std::sin(X * 0.21 + Y * 0.07) * std::cos(Z * 0.17))); });
    EXPECT_NE(windowOf(full), attributes::detail::kFloatIntegerCoding);
    EXPECT_STREQ(attributes::predictedCodingName(attributes::detail::kFloatIntegerCoding), "float integers");
}

} // namespace
} // namespace vdbdag::coding
