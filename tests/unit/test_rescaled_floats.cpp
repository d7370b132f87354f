// attributes/RescaledFloats (window coding 5) against its input: float32
// values on a rescale lattice (k x slope + intercept, as a rescaled scan
// holds them, computed here with plain double arithmetic) come back bit for
// bit, and so do values off it (NaN payloads, -0.0, infinities, denormals,
// an edited value) as exceptions; a window with many of those is left to its
// palettes; corrupt payloads are refused. Through the whole grid codec and
// file, a float grid with a lattice stores its windows as coding 5 and reads
// back exactly; without the hint its windows are palettes or predicted floats.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <vector>

#include "src/attributes/PredictedWindows.h"
#include "src/attributes/RescaledFloats.h"
#include "src/encoding/AttributeLayout.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "tests/unit/PlacedBoxFixture.h"

namespace vdbdag::attributes {
namespace {

constexpr ValueRescale kPet{2.0222414, 0.0};

// The float a scanner's rescale gives for sample k: the product and sum in
// double (each rounded; -ffp-contract=off in this file's build would not
// matter on x86-64 without FMA, and the product is stored first anyway).
float plainRescale(int32_t k, const ValueRescale& r) {
    volatile double product = double(k) * r.slope;
    return float(product + r.intercept);
}

std::vector<uint8_t> bytesOf(const std::vector<float>& v) {
    std::vector<uint8_t> out(v.size() * 4);
    std::memcpy(out.data(), v.data(), out.size());
    return out;
}

// A smooth PET-like field of samples over the placed box, as floats.
coding::testing::PlacedChannel samplesOverBox(uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 20.0);
    return coding::testing::placedBox(rng, true, [&](int X, int Y, int Z) {
        return int32_t(std::max(0.0, 3000 + 2000 * std::sin(X / 6.0) * std::cos(Y / 9.0) + 40 * Z + noise(rng)));
    });
}

std::vector<float> floatsOf(const coding::testing::PlacedChannel& c, const ValueRescale& r) {
    std::vector<float> out;
    for (const int32_t k : c.entries) out.push_back(plainRescale(k, r));
    return out;
}

uint8_t codingOf(const std::vector<uint8_t>& windows, std::span<const uint64_t> layout) {
    const WindowDirectory dir = readPredictedWindowDirectory(windows, 4, layout, "test");
    EXPECT_EQ(dir.windows.size(), 1u);
    return windowRawBytes(windows, dir.windows[0], "test").at(0);
}

TEST(RescaledFloats, LatticeValuesComeBackBitForBitAsTheirIntegers) {
    const auto c = samplesOverBox(3);
    for (const ValueRescale r : {kPet, ValueRescale{0.5, -1024.0}, ValueRescale{-3.25e-3, 7.5}}) {
        const std::vector<uint8_t> bytes = bytesOf(floatsOf(c, r));
        const std::vector<uint8_t> windows = encodePredictedWindows(bytes, 4, c.layout, c.places, FloatChannel{r});
        EXPECT_EQ(codingOf(windows, c.layout), detail::kBandedRescaledFloatCoding) << r.slope;
        EXPECT_EQ(decodePredictedWindows(windows, 4, c.layout, "test", c.places), bytes) << r.slope;
        EXPECT_LT(windows.size(), encodePredictedWindows(bytes, 4, c.layout, c.places).size() * 3 / 4) << "the integers beat the palettes";
    }
}

// The box with its first 8^3 block (Morton bricks 0-7) a tile of sample 0,
// as a scan's import makes a uniform block: stored as coding 20 (coding 16
// with tiles as neighbours), bit for bit.
TEST(RescaledFloats, AWindowWithTilesIsCoding20) {
    auto c = samplesOverBox(4);
    c.layout.erase(c.layout.begin(), c.layout.begin() + 8);
    c.places.erase(c.places.begin(), c.places.begin() + 8);
    c.entries.erase(c.entries.begin(), c.entries.begin() + 8 * 64);
    c.layout.insert(c.layout.begin(), 0);
    c.places.insert(c.places.begin(), coding::tilePlace(0, 0, 0, 3));
    c.entries.insert(c.entries.begin(), 0);
    const std::vector<uint8_t> bytes = bytesOf(floatsOf(c, kPet));
    const std::vector<uint8_t> windows = encodePredictedWindows(bytes, 4, c.layout, c.places, FloatChannel{kPet});
    EXPECT_EQ(codingOf(windows, c.layout), detail::kTiledRescaledFloatCoding);
    EXPECT_EQ(decodePredictedWindows(windows, 4, c.layout, "test", c.places), bytes);
}

TEST(RescaledFloats, ValuesOffTheLatticeAreExceptionsKeptBitForBit) {
    const auto c = samplesOverBox(5);
    std::vector<float> v = floatsOf(c, kPet);
    const float nan = std::bit_cast<float>(0x7FC01234u);  // a quiet NaN with a payload
    const std::vector<std::pair<size_t, float>> odd = {{0, nan},
                                                       {17, -0.0f},
                                                       {4000, std::numeric_limits<float>::infinity()},
                                                       {9000, std::numeric_limits<float>::denorm_min()},
                                                       {20000, v[20000] + 0.25f},
                                                       {32767, -std::numeric_limits<float>::infinity()}};
    for (const auto& [i, x] : odd) v[i] = x;
    const std::vector<uint8_t> bytes = bytesOf(v);
    const std::vector<uint8_t> windows = encodePredictedWindows(bytes, 4, c.layout, c.places, FloatChannel{kPet});
    EXPECT_EQ(codingOf(windows, c.layout), detail::kBandedRescaledFloatCoding);
    EXPECT_EQ(decodePredictedWindows(windows, 4, c.layout, "test", c.places), bytes);
    const auto payload = encodeRescaledFloats(bytes, c.layout, c.places, kPet);
    ASSERT_TRUE(payload);
    uint32_t exceptions = 0;
    std::memcpy(&exceptions, payload->data() + 16, 4);
    EXPECT_EQ(exceptions, odd.size()) << "0 x slope + 0 is +0.0: -0.0 is off the lattice too";
}

TEST(RescaledFloats, AWindowMostlyOffTheLatticeKeepsItsPalettes) {
    const auto c = samplesOverBox(7);
    std::vector<float> v = floatsOf(c, kPet);
    for (size_t i = 0; i < v.size(); i += 8) v[i] = std::nextafter(v[i], 1e30f);  // an eighth off the lattice
    const std::vector<uint8_t> bytes = bytesOf(v);
    EXPECT_FALSE(encodeRescaledFloats(bytes, c.layout, c.places, kPet));
    const std::vector<uint8_t> windows = encodePredictedWindows(bytes, 4, c.layout, c.places, FloatChannel{kPet});
    EXPECT_EQ(codingOf(windows, c.layout), detail::kPaletteCoding);
    EXPECT_EQ(decodePredictedWindows(windows, 4, c.layout, "test", c.places), bytes);
}

TEST(RescaledFloats, CorruptPayloadsAreRefused) {
    const auto c = samplesOverBox(9);
    std::vector<float> v = floatsOf(c, kPet);
    v[10] = std::bit_cast<float>(0x7FC00001u), v[20] = std::bit_cast<float>(0x7FC00002u);
    const std::vector<uint8_t> bytes = bytesOf(v);
    const std::vector<uint8_t> good = *encodeRescaledFloats(bytes, c.layout, c.places, kPet);
    const uint64_t n = c.entries.size();
    EXPECT_EQ(decodeRescaledFloats(good, c.layout, n, "good", c.places, coding::kLatestIntModel), bytes);
    auto zeroSlope = good;
    std::memset(zeroSlope.data(), 0, 8);
    EXPECT_THROW(decodeRescaledFloats(zeroSlope, c.layout, n, "slope", c.places, coding::kLatestIntModel), Error);
    auto nanIntercept = good;
    const uint64_t nanBits = 0x7FF8000000000000ull;
    std::memcpy(nanIntercept.data() + 8, &nanBits, 8);
    EXPECT_THROW(decodeRescaledFloats(nanIntercept, c.layout, n, "intercept", c.places, coding::kLatestIntModel), Error);
    auto swapped = good;  // exceptions out of order: 20 then 10
    std::memcpy(swapped.data() + 20, good.data() + 28, 8);
    std::memcpy(swapped.data() + 28, good.data() + 20, 8);
    EXPECT_THROW(decodeRescaledFloats(swapped, c.layout, n, "order", c.places, coding::kLatestIntModel), Error);
    auto many = good;
    const uint32_t huge = 0xFFFFFFFFu;
    std::memcpy(many.data() + 16, &huge, 4);
    EXPECT_THROW(decodeRescaledFloats(many, c.layout, n, "count", c.places, coding::kLatestIntModel), Error);
    EXPECT_THROW(decodeRescaledFloats(std::span(good).first(30), c.layout, n, "short", c.places, coding::kLatestIntModel), Error);
    EXPECT_THROW(decodeRescaledFloats(good, c.layout, n + 1, "entries", c.places, coding::kLatestIntModel), Error);
}

// A float grid through the codec and the file: with the hint its one window
// is coding 5, without it its palettes or its bits predicted (coding 8),
// whichever is smaller; both read back bit for bit.
TEST(RescaledFloats, AFloatGridWithALatticeStoresItsIntegers) {
    GridRecord record;
    record.name = "pet";
    record.valueType = ValueType::Float;
    record.background = {0, 0, 0, 0};
    record.vdbDescriptor = {1, 2, 3};
    std::mt19937 rng(31);
    for (int z = 0; z < 32; z += 4)
        for (int y = 0; y < 32; y += 4)
            for (int x = 0; x < 32; x += 4) {
                record.topology.bricks.push_back({x, y, z, ~uint64_t(0)});
                for (int i = 0; i < 64; ++i) {
                    const float f = plainRescale(int32_t(1000 + 30 * x + 20 * y + 10 * z + (i & 3) * 5 + int(rng() % 9)), kPet);
                    const auto* p = reinterpret_cast<const uint8_t*>(&f);
                    record.values.bricks.insert(record.values.bricks.end(), p, p + 4);
                }
            }
    for (const bool hint : {true, false}) {
        record.rescale = hint ? std::optional<ValueRescale>(kPet) : std::nullopt;
        format::SsvdagScene scene;
        scene.grids.push_back(pipeline::encodeGrid(record));
        const ValueWindowsPayload& w = scene.grids[0].active.valueWindows;
        EXPECT_TRUE(w.predicted);
        const uint8_t coding = codingOf(w.bytes, encoding::attributeLayout(scene.grids[0].active.dag));
        if (hint) EXPECT_EQ(coding, detail::kBandedRescaledFloatCoding);
        else EXPECT_TRUE(coding == detail::kPaletteCoding || coding == detail::kFloatCoding) << int(coding);
        const format::SsvdagScene back = format::readScene(format::writeScene(scene), "mem");
        const GridRecord decoded = pipeline::decodeGrid(back.grids[0]);
        ASSERT_EQ(decoded.topology.bricks.size(), record.topology.bricks.size());
        // Bricks come back in topology order: compare each brick's values.
        std::map<std::array<int32_t, 3>, std::vector<uint8_t>> expected;
        for (size_t b = 0; b < record.topology.bricks.size(); ++b) {
            const Brick& br = record.topology.bricks[b];
            expected[{br.x, br.y, br.z}].assign(record.values.bricks.begin() + long(256 * b), record.values.bricks.begin() + long(256 * (b + 1)));
        }
        for (size_t b = 0; b < decoded.topology.bricks.size(); ++b) {
            const Brick& br = decoded.topology.bricks[b];
            const std::vector<uint8_t> got(decoded.values.bricks.begin() + long(256 * b), decoded.values.bricks.begin() + long(256 * (b + 1)));
            EXPECT_EQ(got, expected.at({br.x, br.y, br.z})) << "brick at " << br.x << "," << br.y << "," << br.z << " hint " << hint;
        }
    }
}

} // namespace
} // namespace vdbdag::attributes
