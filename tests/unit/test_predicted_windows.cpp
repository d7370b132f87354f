// Predicted windows (src/attributes/PredictedWindows.h): the decoded channel
// equals the input array; windows hold whole bricks and are cut where the
// format says (checked by reading the directory, not through the writer);
// each window takes the smaller coding; the payload does not depend on how
// the entries arrive or on the thread count; damaged payloads are refused
// in one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <random>
#include <string>

#include <tbb/global_control.h>

#include "tests/unit/BuildPaths.h"
#include "src/attributes/PredictedWindows.h"
#include "src/util/Error.h"

using namespace vdbdag;
using attributes::kValueWindowEntries;

namespace {

struct Channel {
    std::vector<uint64_t> layout;  // stored masks, 0 for a solid node
    std::vector<uint8_t> values;   // int32 entries
    uint64_t entries() const { return values.size() / 4; }
};

// Bricks (mostly full, some partial, some solid nodes) until `entries`
// entries: a smooth field plus noise up to `firstLabelEntry`, then a few
// labels (where palettes beat prediction).
Channel makeChannel(uint64_t entries, uint64_t firstLabelEntry, unsigned seed) {
    std::mt19937_64 rng(seed);
    Channel c;
    std::vector<int32_t> v;
    v.reserve(entries + 64);
    while (v.size() < entries) {
        const unsigned kind = unsigned(rng() % 10);
        const uint64_t mask = kind == 0 ? 0 : kind == 1 ? (rng() | 1) : ~uint64_t(0);
        c.layout.push_back(mask);
        const uint64_t brick = c.layout.size();
        for (uint64_t k = 0; k < (mask ? uint64_t(std::popcount(mask)) : 1); ++k) {
            const uint64_t e = v.size();
            if (e < firstLabelEntry) v.push_back(int32_t(1000 + (brick % 4096) / 8 + int32_t(rng() % 7) - 3));
            else v.push_back(int32_t((e / 20000) % 5) * 17);
        }
    }
    c.values.resize(v.size() * 4);
    std::memcpy(c.values.data(), v.data(), c.values.size());
    return c;
}

struct Window {
    uint64_t stored, raw, entries;
};
std::vector<Window> directoryOf(const std::vector<uint8_t>& payload) {
    uint64_t count;
    std::memcpy(&count, payload.data() + 20, 8);
    std::vector<Window> out(count);
    std::memcpy(out.data(), payload.data() + payload.size() - count * 24, count * 24);
    return out;
}

} // namespace

TEST(PredictedWindows, DecodedChannelEqualsTheInputAndWindowsHoldWholeBricks) {
    const Channel c = makeChannel(kValueWindowEntries * 2 + 9999, kValueWindowEntries * 2 + 9999, 1);
    const std::vector<uint8_t> payload = attributes::encodePredictedWindows(c.values, 4, c.layout);
    EXPECT_TRUE(attributes::decodePredictedWindows(payload, 4, c.layout, "test", {}) == c.values);
    // The cuts: window w holds the bricks whose first entry lies in [wE, (w+1)E).
    const std::vector<Window> dir = directoryOf(payload);
    ASSERT_EQ(dir.size(), 3u);
    size_t brick = 0;
    uint64_t entry = 0;
    for (size_t w = 0; w < dir.size(); ++w) {
        uint64_t n = 0;
        while (brick < c.layout.size() && entry < (w + 1) * kValueWindowEntries) {
            const uint64_t e = c.layout[brick] ? std::popcount(c.layout[brick]) : 1;
            n += e, entry += e, ++brick;
        }
        EXPECT_EQ(dir[w].entries, n) << "window " << w;
    }
    EXPECT_EQ(brick, c.layout.size());
    // Smooth plus 3 bits of noise: well under the 4-byte values.
    EXPECT_LT(payload.size(), c.values.size() / 4);
}

TEST(PredictedWindows, EachWindowTakesTheSmallerCoding) {
    // Window 0 smooth noise (prediction wins), windows 1-2 few labels in long runs (palettes win).
    const Channel c = makeChannel(kValueWindowEntries * 3, kValueWindowEntries + 64, 2);
    const std::vector<uint8_t> payload = attributes::encodePredictedWindows(c.values, 4, c.layout);
    EXPECT_TRUE(attributes::decodePredictedWindows(payload, 4, c.layout, "test", {}) == c.values);
    const std::vector<uint8_t> palettesOnly = attributes::encodeValueWindows(c.values, 4);
    // Palettes alone pay for the noise window; the labels windows cost
    // the same either way, so predicted windows are smaller overall.
    EXPECT_LT(payload.size(), palettesOnly.size());
    // Prediction alone pays for the label runs' residual spikes: the label
    // windows here are smaller than the first window's predicted residuals.
    const std::vector<Window> dir = directoryOf(payload);
    ASSERT_GE(dir.size(), 3u);
    EXPECT_LT(dir[1].stored * 20, dir[0].stored);
}

TEST(PredictedWindows, SameBytesHoweverTheEntriesArriveAndWhateverTheThreads) {
    const Channel c = makeChannel(kValueWindowEntries + 4321, kValueWindowEntries / 2, 3);
    const std::vector<uint8_t> whole = attributes::encodePredictedWindows(c.values, 4, c.layout);
    std::mt19937 rng(4);
    for (unsigned parallel : {1u, 2u, 3u}) {
        attributes::PredictedWindowWriter writer(4, parallel);
        size_t entry = 0;
        for (size_t b = 0; b < c.layout.size();) {
            const size_t take = std::min<size_t>(c.layout.size() - b, 1 + rng() % 5000);
            uint64_t n = 0;
            for (size_t k = b; k < b + take; ++k) n += c.layout[k] ? std::popcount(c.layout[k]) : 1;
            writer.add(std::span<const uint8_t>(c.values.data() + entry * 4, n * 4), std::span<const uint64_t>(c.layout.data() + b, take));
            b += take;
            entry += n;
        }
        const attributes::ValueWindowsPayload p = writer.finish();
        EXPECT_TRUE(p.predicted);
        EXPECT_TRUE(p.bytes == whole) << parallel << " windows at a time";
    }
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_TRUE(attributes::encodePredictedWindows(c.values, 4, c.layout) == whole) << "one thread";
}

TEST(PredictedWindows, DamagedPayloadsAreRefused) {
    const Channel c = makeChannel(kValueWindowEntries + 5000, kValueWindowEntries, 5);
    const std::vector<uint8_t> good = attributes::encodePredictedWindows(c.values, 4, c.layout);
    ASSERT_NO_THROW(attributes::decodePredictedWindows(good, 4, c.layout, "good", {}));
    auto refused = [&](std::vector<uint8_t> bytes, const std::string& what, std::span<const uint64_t> layout) {
        try {
            attributes::decodePredictedWindows(bytes, 4, layout, "forged", {});
            ADD_FAILURE() << what << " accepted";
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.rfind("forged", 0), 0u) << what << ": " << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        }
    };
    auto patch = [&](size_t at, uint64_t v) {
        std::vector<uint8_t> b = good;
        std::memcpy(b.data() + at, &v, 8);
        return b;
    };
    const size_t directory = good.size() - 2 * 24;
    refused(patch(4, c.entries() + 1), "more entries than the DAG", c.layout);
    refused(patch(12, 1000), "a window size that is not a power of two", c.layout);
    refused(patch(20, 3), "a window count that does not match", c.layout);
    refused(patch(directory, 12), "a stored size that does not add up", c.layout);
    refused(patch(directory + 8, uint64_t(1) << 50), "an absurd raw size", c.layout);
    {
        std::vector<uint8_t> b = patch(directory + 16, directoryOf(good)[0].entries - 1);
        const uint64_t next = directoryOf(good)[1].entries + 1;
        std::memcpy(b.data() + directory + 24 + 16, &next, 8);
        refused(b, "a window ending inside a brick", c.layout);
    }
    std::vector<uint8_t> truncated(good.begin(), good.end() - 1);
    refused(truncated, "a truncated payload", c.layout);
    std::vector<uint8_t> flipped = good;
    flipped[40] ^= 0x5A;  // inside the first window's zstd frame
    refused(flipped, "a damaged frame", c.layout);
    const std::vector<uint64_t> shorter(c.layout.begin(), c.layout.end() - 1);
    refused(good, "a DAG with a brick fewer", shorter);
}

// Several processes (pipeline/CubeTeam.h): each codes the windows of its
// share and process 0 completes those that straddle shares. Shares cut at
// brick boundaries anywhere (inside a window, on a window boundary, a share
// inside one window, an empty share) give the single writer's bytes.
TEST(PredictedWindows, SharesPutTogetherGiveTheSingleWritersBytes) {
    const Channel c = makeChannel(kValueWindowEntries * 3 + 777, kValueWindowEntries * 2, 7);
    const std::vector<uint8_t> whole = attributes::encodePredictedWindows(c.values, 4, c.layout);
    // Brick index -> first entry.
    std::vector<uint64_t> first(c.layout.size() + 1, 0);
    for (size_t b = 0; b < c.layout.size(); ++b) first[b + 1] = first[b] + (c.layout[b] ? std::popcount(c.layout[b]) : 1);
    auto brickAt = [&](uint64_t entry) { return size_t(std::lower_bound(first.begin(), first.end(), entry) - first.begin()); };
    const std::vector<std::vector<size_t>> splits{
        {brickAt(kValueWindowEntries / 2), brickAt(kValueWindowEntries * 2 + 5)},
        {brickAt(kValueWindowEntries), brickAt(kValueWindowEntries) + 1, brickAt(kValueWindowEntries + 100)},
        {0, brickAt(kValueWindowEntries * 3 - 10)},
        {brickAt(10), brickAt(20), brickAt(30), c.layout.size()}};
    for (const auto& cuts : splits) {
        std::vector<size_t> bounds{0};
        bounds.insert(bounds.end(), cuts.begin(), cuts.end());
        bounds.push_back(c.layout.size());
        attributes::PredictedWindowWriter root(4, 2);
        for (size_t s = 0; s + 1 < bounds.size(); ++s) {
            attributes::PredictedWindowWriter share(4, 2);
            share.beginShare(first[bounds[s]], bounds[s + 1] == c.layout.size());
            share.add(std::span<const uint8_t>(c.values).subspan(size_t(first[bounds[s]] * 4), size_t((first[bounds[s + 1]] - first[bounds[s]]) * 4)),
                      std::span<const uint64_t>(c.layout).subspan(bounds[s], bounds[s + 1] - bounds[s]));
            root.addShare(attributes::ShareWindows::deserialize(share.finishShare().serialize()));
        }
        EXPECT_TRUE(root.finish().bytes == whole) << "shares cut at " << ::testing::PrintToString(cuts);
    }
}

namespace {

// tests/golden/predicted_window_coding3.bin: one int32 channel's predicted
// windows as the writer of 189fcf6 (2026-12-04) wrote them, before bricks
// were visited in spatial order and before the texture bias (one window of
// coding 3, the model of generation 0), written by a program linked with
// that commit's core library: a smooth noisy field over a 16^3 box of full
// bricks in reverse Morton order with random mirrors. Layout: u64 n, n x u64
// masks, n x BrickPlace (4 x u32), the 64 n int32 entries, u64 w, w bytes of
// the PredictedWindows payload.
TEST(PredictedWindows, AWindowOfTheWriterBeforeSpatialOrderStillReads) {
    std::ifstream in(std::string(VDBDAG_SOURCE_DIR) + "/tests/golden/predicted_window_coding3.bin", std::ios::binary);
    ASSERT_TRUE(in);
    const auto read = [&](void* to, size_t bytes) { in.read(static_cast<char*>(to), std::streamsize(bytes)); };
    uint64_t n = 0;
    read(&n, 8);
    ASSERT_EQ(n, 64u);
    std::vector<uint64_t> layout(n);
    std::vector<coding::BrickPlace> places(n);
    std::vector<uint8_t> entries(size_t(64 * 4 * n));
    read(layout.data(), 8 * n), read(places.data(), sizeof(coding::BrickPlace) * n), read(entries.data(), entries.size());
    uint64_t w = 0;
    read(&w, 8);
    std::vector<uint8_t> windows(w);
    read(windows.data(), w);
    ASSERT_TRUE(in);
    const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(windows, 4, layout, "golden");
    ASSERT_EQ(dir.windows.size(), 1u);
    EXPECT_EQ(attributes::windowRawBytes(windows, dir.windows[0], "golden").at(0), attributes::detail::kPlacedContextCoding);
    EXPECT_EQ(attributes::decodePredictedWindows(windows, 4, layout, "golden", places), entries);
    // Today's writer codes the same entries in spatial order, smaller.
    EXPECT_LT(attributes::encodePredictedWindows(entries, 4, layout, places).size(), windows.size());
}

} // namespace
