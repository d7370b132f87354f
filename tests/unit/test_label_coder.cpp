// coding/LabelCoder against its input: a label volume (Voronoi regions of
// random seeds, labels with large and negative ids, a dense box of bricks in
// Morton order, mirrored at random) comes back exactly; it costs a fraction
// of what the numeric coder of the same entries costs (labels have no
// magnitude to predict); a label outside the range is refused; corrupt
// streams are refused or give labels inside the range, never more. Through
// encodePredictedWindows with places, a label window is stored as coding 4
// and decodes exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <random>
#include <vector>

#include "src/attributes/PredictedWindows.h"
#include "src/coding/BrickValueCoder.h"
#include "src/coding/LabelCoder.h"
#include "src/dag/Reflection.h"
#include "tests/unit/PlacedBoxFixture.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using Labels = testing::PlacedChannel;

// Voronoi regions of random seeds over the placed box (PlacedBoxFixture.h),
// every 97th brick (from the 6th) a tile of the first label.
Labels voronoi(uint32_t seed, int regions) {
    std::mt19937 rng(seed);
    std::vector<std::array<int, 3>> centres(static_cast<size_t>(regions));
    std::vector<int32_t> ids(static_cast<size_t>(regions));
    for (int r = 0; r < regions; ++r) {
        centres[size_t(r)] = {int(rng() % 32), int(rng() % 32), int(rng() % 32)};
        ids[size_t(r)] = int32_t(rng() % 200000) - 100000;
    }
    return testing::placedBox(
        rng, true,
        [&](int X, int Y, int Z) {
            int best = 0, bestD = 1 << 30;
            for (int r = 0; r < regions; ++r) {
                const auto& c = centres[size_t(r)];
                const int d = (X - c[0]) * (X - c[0]) + (Y - c[1]) * (Y - c[1]) + (Z - c[2]) * (Z - c[2]);
                if (d < bestD) bestD = d, best = r;
            }
            return ids[size_t(best)];
        },
        97, 5, ids[0]);
}

TEST(LabelCoder, LabelVolumesComeBackExactlyForAFractionOfTheNumericCost) {
    for (int regions : {1, 12, 60}) {
        const Labels l = voronoi(uint32_t(regions), regions);
        const auto [lo, hi] = std::minmax_element(l.entries.begin(), l.entries.end());
        const std::vector<uint8_t> bytes = encodePlacedLabels(l.entries, l.layout, l.places, *lo, *hi);
        std::vector<int32_t> back(l.entries.size());
        decodePlacedLabels(bytes, l.layout, l.places, *lo, *hi, back, "labels");
        EXPECT_EQ(back, l.entries) << regions;
        IntCoderOptions o;
        o.minValue = *lo, o.maxValue = *hi;
        const size_t numeric = encodePlacedBrickValues(l.entries, l.layout, l.places, o).size();
        if (regions > 1) EXPECT_LT(bytes.size() * 2, numeric) << regions << " regions: labels " << bytes.size() << ", numeric " << numeric;
        else EXPECT_LT(bytes.size(), 100u);  // one label: next to nothing
    }
}

TEST(LabelCoder, OutOfRangeLabelsAndCorruptStreamsAreRefused) {
    const Labels l = voronoi(3, 20);
    const auto [lo, hi] = std::minmax_element(l.entries.begin(), l.entries.end());
    EXPECT_THROW(encodePlacedLabels(l.entries, l.layout, l.places, *lo + 1, *hi), Error);
    const std::vector<uint8_t> bytes = encodePlacedLabels(l.entries, l.layout, l.places, *lo, *hi);
    std::vector<int32_t> back(l.entries.size());
    EXPECT_THROW(decodePlacedLabels(std::vector<uint8_t>(bytes.begin(), bytes.begin() + ptrdiff_t(bytes.size() / 2)), l.layout, l.places, *lo, *hi, back, "half"),
                 Error);
    std::mt19937 rng(4);
    for (int trial = 0; trial < 20; ++trial) {
        std::vector<uint8_t> garbage(bytes.size());
        for (auto& b : garbage) b = uint8_t(rng());
        try {
            decodePlacedLabels(garbage, l.layout, l.places, *lo, *hi, back, "garbage");
            for (int32_t v : back) ASSERT_TRUE(v >= *lo && v <= *hi);
        } catch (const Error&) {
        }
    }
}

TEST(LabelCoder, PredictedWindowsStoreLabelsAsCoding4) {
    const Labels l = voronoi(5, 30);
    std::vector<uint8_t> bytes(l.entries.size() * 4);
    std::memcpy(bytes.data(), l.entries.data(), bytes.size());
    const std::vector<uint8_t> windows = attributes::encodePredictedWindows(bytes, 4, l.layout, l.places);
    const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(windows, 4, l.layout, "test");
    ASSERT_EQ(dir.windows.size(), 1u);
    EXPECT_EQ(windows[size_t(dir.windows[0].offset)], attributes::detail::kPlacedLabelCoding);
    EXPECT_EQ(attributes::decodePredictedWindows(windows, 4, l.layout, "test", l.places), bytes);
    EXPECT_THROW(attributes::decodePredictedWindows(windows, 4, l.layout, "test", {}), Error);  // a label window needs its places
}

} // namespace
} // namespace vdbdag::coding
