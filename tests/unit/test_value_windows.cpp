// Value windows (src/attributes/ValueWindows.h): the merged channel gives
// back every entry (against the input array), the payload does not depend on
// how the entries arrive or on the thread count, and damaged payloads are
// refused in one line.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include <tbb/global_control.h>

#include "src/attributes/ValueWindows.h"
#include "src/attributes/WindowCursor.h"
#include "src/util/Error.h"

using namespace vdbdag;
using attributes::kValueWindowEntries;

namespace {

// Floats with long runs, few-valued stretches and unique noise, so palette
// and whole-material-array blocks occur in each window.
std::vector<uint8_t> mixedFloats(uint64_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<float> v(n);
    for (uint64_t i = 0; i < n; ++i) {
        const uint64_t stretch = (i / 5000) % 3;
        if (stretch == 0) v[i] = float((i / 700) % 4);
        else if (stretch == 1) v[i] = float(rng() % 3000) * 0.5f;
        else v[i] = std::uniform_real_distribution<float>(-1, 1)(rng);
    }
    std::vector<uint8_t> bytes(n * 4);
    std::memcpy(bytes.data(), v.data(), bytes.size());
    return bytes;
}

} // namespace

TEST(ValueWindows, MergedChannelGivesBackEveryEntry) {
    const uint64_t n = kValueWindowEntries * 2 + 12345;  // three windows, the last one short
    const std::vector<uint8_t> values = mixedFloats(n, 1);
    const std::vector<uint8_t> payload = attributes::encodeValueWindows(values, 4);
    const attributes::PaletteChannel c = attributes::decodeValueWindows(payload, "test");
    EXPECT_EQ(c.entryCount, n);
    EXPECT_TRUE(c.decodeAll() == values);
    std::mt19937_64 rng(2);
    size_t hint = 0;
    for (int k = 0; k < 20000; ++k) {
        const uint64_t i = rng() % n;
        uint8_t got[4];
        c.lookup(i, got, hint);
        ASSERT_EQ(std::memcmp(got, values.data() + i * 4, 4), 0) << "entry " << i;
    }
    bool whole = false, palette = false;
    for (const auto& b : c.blocks) {
        palette |= b.indexBits != attributes::PaletteBlock::kDirect && b.indexBits <= 8;
        whole |= b.indexBits != attributes::PaletteBlock::kDirect && b.indexBits > 8;  // a window's whole-material-array blocks, merged
        EXPECT_NE(b.paletteOffset, attributes::PaletteBlock::kWholeMaterialArray);
    }
    EXPECT_TRUE(whole && palette) << whole << palette;
    // Smaller than the raw floats (runs and few-valued stretches; a third is unique noise).
    EXPECT_LT(payload.size(), values.size() * 3 / 4);
}

TEST(ValueWindows, SameBytesHoweverTheEntriesArriveAndWhateverTheThreads) {
    const uint64_t n = kValueWindowEntries + 777;
    const std::vector<uint8_t> values = mixedFloats(n, 3);
    const std::vector<uint8_t> whole = attributes::encodeValueWindows(values, 4);
    std::mt19937 rng(4);
    for (unsigned parallel : {1u, 2u, 3u}) {
        attributes::ValueWindowWriter writer(4, parallel == 2 ? 0 : n, parallel);
        for (uint64_t at = 0; at < n;) {
            const uint64_t take = std::min<uint64_t>(n - at, 1 + rng() % 300000);
            writer.add(std::span<const uint8_t>(values.data() + at * 4, take * 4));
            at += take;
        }
        EXPECT_TRUE(writer.finish().bytes == whole) << parallel << " windows at a time";
    }
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        EXPECT_TRUE(attributes::encodeValueWindows(values, 4) == whole) << "one thread";
    }
}

TEST(ValueWindows, DamagedPayloadsAreRefused) {
    const std::vector<uint8_t> values = mixedFloats(kValueWindowEntries + 5000, 5);
    const std::vector<uint8_t> good = attributes::encodeValueWindows(values, 4);
    ASSERT_NO_THROW(attributes::decodeValueWindows(good, "good"));
    auto refused = [](std::vector<uint8_t> bytes, const std::string& what) {
        try {
            attributes::decodeValueWindows(bytes, "forged");
            ADD_FAILURE() << what << " accepted";
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.rfind("forged", 0), 0u) << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        }
    };
    auto patch = [&](size_t at, uint64_t v) {
        std::vector<uint8_t> b = good;
        std::memcpy(b.data() + at, &v, 8);
        return b;
    };
    const size_t directory = good.size() - 2 * 16;
    refused(patch(4, kValueWindowEntries * 3), "more entries than the windows");
    refused(patch(12, 1000), "a window size that is not a power of two");
    refused(patch(20, 3), "a window count that does not match");
    refused(patch(directory, 12), "a stored size that does not add up");
    refused(patch(directory + 8, uint64_t(1) << 50), "an absurd raw size");
    std::vector<uint8_t> truncated(good.begin(), good.end() - 1);
    refused(truncated, "a truncated payload");
    std::vector<uint8_t> flipped = good;
    flipped[40] ^= 0x5A;  // inside the first window's zstd frame
    refused(flipped, "a damaged frame");
}

// Several processes: shares cut anywhere give the single writer's bytes
// (PredictedWindows' test has the brick-aligned case).
TEST(ValueWindows, SharesPutTogetherGiveTheSingleWritersBytes) {
    const uint64_t n = kValueWindowEntries * 3 + 999;
    const std::vector<uint8_t> values = mixedFloats(n, 8);
    const std::vector<uint8_t> whole = attributes::encodeValueWindows(values, 4);
    const std::vector<std::vector<uint64_t>> splits{{kValueWindowEntries / 3, kValueWindowEntries * 2 + 1},
                                                    {kValueWindowEntries, kValueWindowEntries + 1, kValueWindowEntries + 2},
                                                    {0, n - 5},
                                                    {7, 8, 9, n}};
    for (const auto& cuts : splits) {
        std::vector<uint64_t> bounds{0};
        bounds.insert(bounds.end(), cuts.begin(), cuts.end());
        bounds.push_back(n);
        attributes::ValueWindowWriter root(4, n, 2);
        for (size_t s = 0; s + 1 < bounds.size(); ++s) {
            attributes::ValueWindowWriter share(4, 0, 2);
            share.beginShare(bounds[s], bounds[s + 1] == n);
            share.add(std::span<const uint8_t>(values).subspan(size_t(bounds[s] * 4), size_t((bounds[s + 1] - bounds[s]) * 4)));
            root.addShare(attributes::ShareWindows::deserialize(share.finishShare().serialize()));
        }
        EXPECT_TRUE(root.finish().bytes == whole) << "shares cut at " << ::testing::PrintToString(cuts);
    }
}

// A cursor reads the windows in order, one decoded at a time or with
// windows decoding ahead on other threads (WindowCursor.h): every entry
// back, against the input, in uneven reads that cross windows, whatever
// the read-ahead; and a damaged window is refused the same way.
TEST(ValueWindows, ACursorGivesBackEveryEntryWhateverItsReadAhead) {
    const uint64_t n = kValueWindowEntries * 3 + 4321;  // four windows
    const std::vector<uint8_t> values = mixedFloats(n, 7);
    const std::vector<uint8_t> payload = attributes::encodeValueWindows(values, 4);
    for (const unsigned ahead : {0u, 1u, 3u, 7u}) {
        attributes::WindowCursor cursor(payload, false, 4, {}, "test", {}, ahead);
        ASSERT_EQ(cursor.entries(), n);
        std::vector<uint8_t> back(values.size());
        uint64_t at = 0;
        for (uint64_t step = 1; at < n; step = step * 3 + 1) {  // 1, 4, 13, ... entries a read
            const uint64_t take = std::min(step % (kValueWindowEntries + 7), n - at);
            cursor.read(take, back.data() + at * 4);
            at += take;
        }
        EXPECT_TRUE(back == values) << "ahead " << ahead;
        EXPECT_THROW(cursor.read(1, back.data()), Error) << "ahead " << ahead;
    }
    // The third window's bytes damaged: the same refusal, read ahead or not.
    std::vector<uint8_t> damaged = payload;
    std::string first;
    for (size_t at = payload.size() / 2; at < payload.size() / 2 + 64 && first.empty(); ++at) {
        damaged = payload;
        damaged[at] ^= 0x5A;
        try {
            attributes::decodeValueWindows(damaged, "test");
        } catch (const Error& e) {
            first = e.what();
        }
    }
    ASSERT_FALSE(first.empty()) << "no byte in the middle of the payload is checked";
    for (const unsigned ahead : {0u, 3u}) {
        std::string got;
        try {
            attributes::WindowCursor cursor(damaged, false, 4, {}, "test", {}, ahead);
            std::vector<uint8_t> back(values.size());
            cursor.read(n, back.data());
        } catch (const Error& e) {
            got = e.what();
        }
        EXPECT_FALSE(got.empty()) << "ahead " << ahead;
        EXPECT_EQ(got.rfind("test", 0), 0u) << got;
    }
}
