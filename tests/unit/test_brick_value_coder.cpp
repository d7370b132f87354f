// src/coding/BrickValueCoder and the predicted windows' coding 2
// (attributes/ContextChannel.h) against their input: every entry back
// exactly (lossless) or within `near` (checked on every entry), over layouts
// that exercise every neighbour rule (full bricks, sparse random masks,
// single voxels, tiles between bricks); closed-form bounds where the answer
// is known (a constant channel costs almost nothing, 8-bit noise not below
// 8 bits); a layout that disagrees with the entries, corrupt, truncated and
// padded streams refused. The same smooth int32 channel through
// encodePredictedWindows is stored as coding 2 and is smaller than the
// brick-MED coding (1) of the same windows. With their places (a dense box
// of mirrored bricks), neighbours across bricks: exact, within near, smaller.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "src/attributes/ContextChannel.h"
#include "src/attributes/PredictedChannel.h"
#include "src/attributes/PredictedWindows.h"
#include "src/coding/BrickValueCoder.h"
#include "src/dag/Reflection.h"
#include "tests/unit/PlacedBoxFixture.h"
#include "src/format/ZstdFrame.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

// Bricks of a smooth field with noise; every 7th instance a tile, every
// 5th a sparse random mask.
struct Channel {
    std::vector<uint64_t> layout;
    std::vector<int32_t> entries;
};

Channel smoothChannel(size_t bricks, uint32_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, 4.0);
    Channel c;
    for (size_t b = 0; b < bricks; ++b) {
        uint64_t mask = ~uint64_t(0);
        if (b % 7 == 3) mask = 0;
        else if (b % 5 == 1) mask = rng() & rng();
        c.layout.push_back(mask);
        const double base = 1000.0 * std::sin(double(b) * 0.01);
        if (mask == 0) {
            c.entries.push_back(int32_t(std::lround(base)));
            continue;
        }
        for (uint64_t bits = mask; bits; bits &= bits - 1) {
            const int i = std::countr_zero(bits), x = i & 3, y = (i >> 2) & 3, z = i >> 4;
            c.entries.push_back(int32_t(std::lround(base + 30.0 * x - 20.0 * y + 10.0 * z + noise(rng))));
        }
    }
    return c;
}

void expectRoundTrip(const Channel& c, IntCoderOptions o, const std::string& what) {
    std::vector<int32_t> reconstructed;
    const std::vector<uint8_t> bytes = encodeBrickValues(c.entries, c.layout, o, &reconstructed);
    std::vector<int32_t> back(c.entries.size());
    decodeBrickValues(bytes, c.layout, o, back, what);
    EXPECT_EQ(back, reconstructed) << what << ": the decoder differs from the encoder's reconstruction";
    size_t outside = 0;
    for (size_t i = 0; i < back.size(); ++i) outside += std::abs(int64_t(back[i]) - c.entries[i]) > o.near;
    EXPECT_EQ(outside, 0u) << what << ": entries beyond near = " << o.near;
    if (o.near == 0) { EXPECT_EQ(back, c.entries) << what; }
}

TEST(BrickValueCoder, LosslessAndNearLosslessOverEveryKindOfBrick) {
    const Channel c = smoothChannel(900, 1);
    ASSERT_EQ(layoutEntryCount(c.layout), c.entries.size());
    for (int32_t near : {0, 1, 2, 9}) {
        IntCoderOptions o;
        o.minValue = -1200, o.maxValue = 1300, o.near = near;
        expectRoundTrip(c, o, "near " + std::to_string(near));
    }
    // One voxel, one tile, nothing.
    expectRoundTrip({{uint64_t(1) << 63}, {-7}}, {}, "one voxel");
    expectRoundTrip({{0}, {INT32_MIN}}, {}, "one tile");
    expectRoundTrip({{}, {}}, {}, "empty");
}

TEST(BrickValueCoder, ExtremesAndNoiseRoundTripNoiseCostsItsBits) {
    std::mt19937 rng(5);
    Channel c;
    for (int b = 0; b < 40; ++b) c.layout.push_back(~uint64_t(0));
    for (size_t i = 0; i < 40 * 64; ++i) c.entries.push_back(int32_t(rng()));
    c.entries[0] = INT32_MIN, c.entries[1] = INT32_MAX, c.entries[64] = INT32_MAX;
    expectRoundTrip(c, {}, "int32 noise");
    // 8-bit white noise over 400 bricks: no coder gets below 8 bits an entry.
    c.layout.assign(400, ~uint64_t(0));
    c.entries.resize(400 * 64);
    for (auto& v : c.entries) v = int32_t(rng() & 255u);
    IntCoderOptions u8;
    u8.minValue = 0, u8.maxValue = 255;
    const size_t coded = encodeBrickValues(c.entries, c.layout, u8).size();
    EXPECT_GE(coded, c.entries.size() * 99 / 100);  // entropy: 8 bits an entry
    EXPECT_LE(coded, c.entries.size() * 112 / 100);
    expectRoundTrip(c, u8, "u8 noise");
}

TEST(BrickValueCoder, AConstantChannelCostsAlmostNothing) {
    Channel c;
    for (int b = 0; b < 4096; ++b) c.layout.push_back(b % 9 ? ~uint64_t(0) : 0);
    c.entries.assign(layoutEntryCount(c.layout), -1024);
    IntCoderOptions o;
    o.minValue = -1024, o.maxValue = 3071;
    EXPECT_LT(encodeBrickValues(c.entries, c.layout, o).size(), 400u);  // ~233,000 zero residuals
    expectRoundTrip(c, o, "constant");
}

TEST(BrickValueCoder, DisagreeingLayoutsAndBadStreamsAreRefused) {
    const Channel c = smoothChannel(200, 2);
    IntCoderOptions o;
    o.minValue = -1200, o.maxValue = 1300;
    std::vector<int32_t> shorter(c.entries.begin(), c.entries.end() - 1);
    EXPECT_THROW(encodeBrickValues(shorter, c.layout, o), Error);
    std::vector<int32_t> outside = c.entries;
    outside[10] = 1301;
    EXPECT_THROW(encodeBrickValues(outside, c.layout, o), Error);
    const std::vector<uint8_t> bytes = encodeBrickValues(c.entries, c.layout, o);
    std::vector<int32_t> back(c.entries.size());
    EXPECT_THROW(decodeBrickValues(std::vector<uint8_t>(bytes.begin(), bytes.begin() + ptrdiff_t(bytes.size() / 2)), c.layout, o, back, "half"), Error);
    std::vector<uint8_t> padded = bytes;
    padded.resize(bytes.size() + 64, 0x5A);
    EXPECT_THROW(decodeBrickValues(padded, c.layout, o, back, "padded"), Error);
    std::vector<int32_t> wrongCount(c.entries.size() + 1);
    EXPECT_THROW(decodeBrickValues(bytes, c.layout, o, wrongCount, "count"), Error);
    std::vector<uint8_t> garbage(bytes.size());
    std::mt19937 rng(3);
    for (auto& b : garbage) b = uint8_t(rng());
    try {
        decodeBrickValues(garbage, c.layout, o, back, "garbage");
        for (int32_t v : back) EXPECT_TRUE(v >= o.minValue && v <= o.maxValue);
    } catch (const Error&) {
    }
}

// A predicted window of smooth int32 values is context coded (coding 2),
// decodes exactly, and is smaller than the same window's brick MED + zstd.
TEST(BrickValueCoder, PredictedWindowsStoreInt32AsCoding2) {
    const Channel c = smoothChannel(3000, 4);
    std::vector<uint8_t> bytes(c.entries.size() * 4);
    std::memcpy(bytes.data(), c.entries.data(), bytes.size());
    const std::vector<uint8_t> windows = attributes::encodePredictedWindows(bytes, 4, c.layout);
    const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(windows, 4, c.layout, "test");
    ASSERT_EQ(dir.windows.size(), 1u);
    const auto& w = dir.windows[0];
    ASSERT_EQ(w.stored, w.raw);  // range coded: stored as it is
    EXPECT_EQ(windows[size_t(w.offset)], attributes::detail::kContextCoding);
    EXPECT_EQ(attributes::decodePredictedWindows(windows, 4, c.layout, "test", {}), bytes);
    const std::vector<uint8_t> med = attributes::encodePredicted(bytes, 4, c.layout);
    EXPECT_LT(w.stored, format::zstdCompressIfSmaller(med, {9, true, 0}).size());
    // The payload checks its entry count against the window's.
    const std::vector<uint8_t> payload = attributes::encodeContextChannel(bytes, c.layout);
    EXPECT_THROW(attributes::decodeContextChannel(payload, c.layout, c.entries.size() + 1, "test"), Error);
}

} // namespace
} // namespace vdbdag::coding

namespace vdbdag::coding {
namespace {

using testing::PlacedChannel;
using testing::placedBlockBox;

// A smooth field with noise over the placed box (PlacedBoxFixture.h).
PlacedChannel placedField(uint32_t seed, bool mirrors) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 3.0);
    return testing::placedBox(rng, mirrors, [&](int X, int Y, int Z) {
        return int32_t(std::lround(500 + 200 * std::sin(X / 7.0) + 150 * std::cos(Y / 5.0) + 3 * Z + noise(rng)));
    });
}

// A layout visited from the far corner (as a DAG under mirrors visits its
// children): in the layout's order a brick's W, N and P bricks come after
// it; in spatial order the walk is the forward box's, byte for byte, and
// smaller.
TEST(BrickValueCoder, SpatialOrderUndoesALayoutVisitedFromTheFarCorner) {
    const PlacedChannel forward = placedField(13, true);
    const PlacedChannel backward = testing::reversedBricks(forward);
    IntCoderOptions o;
    o.minValue = -100, o.maxValue = 1100;
    const std::vector<uint8_t> spatial = encodePlacedBrickValues(backward.entries, backward.layout, backward.places, BrickOrder::Spatial, o);
    const std::vector<uint8_t> layoutOrder = encodePlacedBrickValues(backward.entries, backward.layout, backward.places, BrickOrder::Attribute, o);
    EXPECT_EQ(spatial, encodePlacedBrickValues(forward.entries, forward.layout, forward.places, BrickOrder::Spatial, o));
    EXPECT_LT(spatial.size(), layoutOrder.size() * 95 / 100);
    for (const BrickOrder order : {BrickOrder::Spatial, BrickOrder::Attribute}) {
        std::vector<int32_t> back(backward.entries.size());
        decodePlacedBrickValues(order == BrickOrder::Spatial ? spatial : layoutOrder, backward.layout, backward.places, order, o, back, "order");
        EXPECT_EQ(back, backward.entries);
    }
}

TEST(BrickValueCoder, PlacedBricksRoundTripAndSeeAcrossBrickBoundaries) {
    for (bool mirrors : {false, true}) {
        const PlacedChannel c = placedField(9, mirrors);
        for (int32_t near : {0, 2}) {
            IntCoderOptions o;
            o.minValue = -100, o.maxValue = 1100, o.near = near;
            std::vector<int32_t> reconstructed;
            const std::vector<uint8_t> bytes = encodePlacedBrickValues(c.entries, c.layout, c.places, BrickOrder::Spatial, o, &reconstructed);
            std::vector<int32_t> back(c.entries.size());
            decodePlacedBrickValues(bytes, c.layout, c.places, BrickOrder::Spatial, o, back, "placed");
            EXPECT_EQ(back, reconstructed);
            size_t outside = 0;
            for (size_t i = 0; i < back.size(); ++i) outside += std::abs(int64_t(back[i]) - c.entries[i]) > near;
            EXPECT_EQ(outside, 0u) << "mirrors " << mirrors << " near " << near;
            if (near == 0) {
                // Neighbours across bricks make it smaller than each brick alone.
                const size_t alone = encodeBrickValues(c.entries, c.layout, o).size();
                EXPECT_LT(bytes.size(), alone * 95 / 100) << "mirrors " << mirrors;
            }
        }
    }
}

// Coding 19: model generation 4's placed walk with tiles as neighbours, on a
// 32^3 box whose 8^3 blocks with x < 8 are zero tiles (tilePlace, 8 wide)
// and the others 8 mirrored bricks of a noisy ramp (blocks and bricks in
// Morton order): every entry back exactly, or within near; a window with
// tiles is stored as coding 19 and reads back; tile neighbours on another
// generation's walk are refused.
TEST(BrickValueCoder, TilesAreNeighboursInCoding19) {
    std::mt19937 rng(19);
    const PlacedChannel c = placedBlockBox(rng, [](int X, int Y, int Z) {
        const uint32_t noise = (uint32_t(X) * 73856093u ^ uint32_t(Y) * 19349663u ^ uint32_t(Z) * 83492791u) % 9;  // the same each time asked
        return X < 8 ? 0 : int32_t(20 * X + 3 * Y + int(noise));
    });
    for (int32_t near : {0, 2}) {
        IntCoderOptions o;
        o.minValue = 0, o.maxValue = 1000, o.near = near, o.model = 4, o.tileNeighbours = true;
        std::vector<int32_t> reconstructed;
        const std::vector<uint8_t> bytes = encodePlacedBrickValues(c.entries, c.layout, c.places, BrickOrder::Raster, o, &reconstructed);
        std::vector<int32_t> back(c.entries.size());
        decodePlacedBrickValues(bytes, c.layout, c.places, BrickOrder::Raster, o, back, "tiled");
        EXPECT_EQ(back, reconstructed);
        size_t outside = 0;
        for (size_t i = 0; i < back.size(); ++i) outside += std::abs(int64_t(back[i]) - c.entries[i]) > near;
        EXPECT_EQ(outside, 0u) << "near " << near;
        o.model = 3;
        EXPECT_THROW(encodePlacedBrickValues(c.entries, c.layout, c.places, BrickOrder::Raster, o), Error);
    }
    std::vector<uint8_t> raw(c.entries.size() * 4);
    std::memcpy(raw.data(), c.entries.data(), raw.size());
    const std::vector<uint8_t> windows = attributes::encodePredictedWindows(raw, 4, c.layout, c.places);
    const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(windows, 4, c.layout, "test");
    ASSERT_EQ(dir.windows.size(), 1u);
    EXPECT_EQ(windows[size_t(dir.windows[0].offset)], attributes::detail::kTiledContextCoding);
    EXPECT_EQ(attributes::decodePredictedWindows(windows, 4, c.layout, "test", c.places), raw);
}

// A series' reference (IntCoderOptions::reference in the placed walk;
// window codings 21 and 22, FORMAT.md 8.6): a volume of rough texture and
// the next one, the same texture moved by at most 2 per voxel, over the
// same 32^3 box of mirrored bricks and zero tiles. With the first as its
// reference the second codes under 0.6 times its size alone; every entry
// comes back (within near); a reference of the wrong length is refused.
// In windows: the pass's re-coding stores coding 21, which decodes with the
// reference's windows and is refused without them.
TEST(BrickValueCoder, ASeriesReferenceTakesTheVolumeBeforeAsNeighbours) {
    const auto texture = [](int X, int Y, int Z) { return int32_t((uint32_t(X) * 73856093u ^ uint32_t(Y) * 19349663u ^ uint32_t(Z) * 83492791u) % 20000); };
    std::mt19937 rngA(21), rngB(21);  // the same mirrors: the same layout and places
    const PlacedChannel a = placedBlockBox(rngA, [&](int X, int Y, int Z) { return X < 8 ? 0 : 100 + texture(X, Y, Z); });
    const PlacedChannel b = placedBlockBox(rngB, [&](int X, int Y, int Z) { return X < 8 ? 0 : 100 + texture(X, Y, Z) + int32_t((X + 2 * Y + 3 * Z) % 5) - 2; });
    ASSERT_EQ(a.layout, b.layout);
    for (int32_t near : {0, 2}) {
        IntCoderOptions o;
        o.minValue = 0, o.maxValue = 30000, o.near = near, o.model = 4, o.tileNeighbours = true;
        const size_t alone = encodePlacedBrickValues(b.entries, b.layout, b.places, BrickOrder::Raster, o).size();
        o.reference = a.entries;
        std::vector<int32_t> reconstructed;
        const std::vector<uint8_t> bytes = encodePlacedBrickValues(b.entries, b.layout, b.places, BrickOrder::Raster, o, &reconstructed);
        if (near == 0) {
            EXPECT_LT(double(bytes.size()), 0.6 * double(alone)) << bytes.size() << " against " << alone;
        }
        std::vector<int32_t> back(b.entries.size());
        decodePlacedBrickValues(bytes, b.layout, b.places, BrickOrder::Raster, o, back, "referenced");
        EXPECT_EQ(back, reconstructed);
        size_t outside = 0;
        for (size_t i = 0; i < back.size(); ++i) outside += std::abs(int64_t(back[i]) - b.entries[i]) > near;
        EXPECT_EQ(outside, 0u) << "near " << near;
        const std::vector<int32_t> shorter(a.entries.begin(), a.entries.end() - 1);
        o.reference = shorter;
        EXPECT_THROW(decodePlacedBrickValues(bytes, b.layout, b.places, BrickOrder::Raster, o, back, "short"), Error);
    }
    const auto raw = [](const std::vector<int32_t>& v) {
        std::vector<uint8_t> out(v.size() * 4);
        std::memcpy(out.data(), v.data(), out.size());
        return out;
    };
    const std::vector<uint8_t> windowsA = attributes::encodePredictedWindows(raw(a.entries), 4, a.layout, a.places);
    const std::vector<uint8_t> windowsB = attributes::encodePredictedWindows(raw(b.entries), 4, b.layout, b.places);
    const auto whole = [&](const std::vector<int32_t>& v) { return [all = raw(v)](size_t) { return all; }; };  // one window each
    uint64_t referenced = 0;
    const std::optional<std::vector<uint8_t>> coded =
        attributes::referencePredictedWindows(windowsB, whole(b.entries), whole(a.entries), 4, b.layout, b.places, "test", referenced);
    ASSERT_TRUE(coded);
    EXPECT_EQ(referenced, 1u);
    EXPECT_LT(coded->size(), windowsB.size());
    const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(*coded, 4, b.layout, "test");
    ASSERT_EQ(dir.windows.size(), 1u);
    const std::vector<uint8_t> first = dir.windows[0].stored == dir.windows[0].raw
                                           ? std::vector<uint8_t>{(*coded)[size_t(dir.windows[0].offset)]}
                                           : format::zstdFirstBytes(std::span<const uint8_t>(*coded).subspan(size_t(dir.windows[0].offset), size_t(dir.windows[0].stored)), 1, "test");
    EXPECT_EQ(first.at(0), attributes::detail::kReferencedContextCoding);
    const auto reference = std::make_shared<const attributes::WindowReference>(windowsA, 4, a.layout, nullptr, "reference");
    EXPECT_EQ(attributes::decodePredictedWindows(*coded, 4, b.layout, "test", b.places, {}, attributes::referenceWindows(reference, a.layout, a.places)),
              raw(b.entries));
    EXPECT_THROW(attributes::decodePredictedWindows(*coded, 4, b.layout, "test", b.places), Error);
}

TEST(BrickValueCoder, PlacesThatAreNoBricksAreRefused) {
    PlacedChannel c = placedField(4, true);
    IntCoderOptions o;
    o.minValue = -100, o.maxValue = 1100;
    PlacedChannel twice = c;
    twice.places[7] = twice.places[3];
    EXPECT_THROW(encodePlacedBrickValues(twice.entries, twice.layout, twice.places, BrickOrder::Spatial, o), Error);
    PlacedChannel off = c;
    off.places[5].x += 1;
    EXPECT_THROW(encodePlacedBrickValues(off.entries, off.layout, off.places, BrickOrder::Spatial, o), Error);
    PlacedChannel fewer = c;
    fewer.places.pop_back();
    EXPECT_THROW(encodePlacedBrickValues(fewer.entries, fewer.layout, fewer.places, BrickOrder::Spatial, o), Error);
    const std::vector<uint8_t> bytes = encodePlacedBrickValues(c.entries, c.layout, c.places, BrickOrder::Spatial, o);
    std::vector<int32_t> back(c.entries.size());
    EXPECT_THROW(decodePlacedBrickValues(bytes, twice.layout, twice.places, BrickOrder::Spatial, o, back, "twice"), Error);
}

} // namespace
} // namespace vdbdag::coding

namespace vdbdag::attributes {
namespace {

// Entries sharing a step above their minimum (values quantised by
// --abs-error, or a scanner's multiples): the payload records the step (its
// greatest common divisor, offset 5) and codes the quotients; exact back.
TEST(ContextChannel, ACommonStepIsDividedOut) {
    std::vector<uint64_t> layout(50, ~uint64_t(0));
    std::vector<int32_t> v(50 * 64);
    std::mt19937 rng(8);
    for (size_t i = 0; i < v.size(); ++i) v[i] = -1000 + 7 * int32_t(200 + (i % 64) + rng() % 5);
    std::vector<uint8_t> bytes(v.size() * 4);
    std::memcpy(bytes.data(), v.data(), bytes.size());
    const std::vector<uint8_t> payload = encodeContextChannel(bytes, layout);
    uint32_t step;
    std::memcpy(&step, payload.data() + 5, 4);
    EXPECT_EQ(step, 7u);
    EXPECT_EQ(decodeContextChannel(payload, layout, v.size(), "step"), bytes);
    // A step that does not divide the range is refused.
    std::vector<uint8_t> forged = payload;
    const uint32_t three = 3;
    std::memcpy(forged.data() + 5, &three, 4);
    EXPECT_THROW(decodeContextChannel(forged, layout, v.size(), "forged"), Error);
}

} // namespace
} // namespace vdbdag::attributes
