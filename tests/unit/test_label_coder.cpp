// coding/LabelCoder against its input: a label volume (Voronoi regions of
// random seeds, labels with large and negative ids, a dense box of bricks in
// Morton order, mirrored at random) comes back exactly; it costs a fraction
// of what the numeric coder of the same entries costs (labels have no
// magnitude to predict); a label outside the range is refused; corrupt
// streams are refused or give labels inside the range, never more; each
// for label model generations 1, 2 and 3 (3: tiles as neighbours, on a box
// whose uniform 8^3 blocks are tiles). Through encodePredictedWindows with
// places, a label window is stored as coding 18 and decodes exactly; ones
// of codings 17, 7 and 4 (older writers') still do.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <random>
#include <vector>

#include "src/attributes/ContextChannel.h"
#include "src/attributes/PredictedWindows.h"
#include "src/coding/BrickValueCoder.h"
#include "src/coding/LabelCoder.h"
#include "src/dag/Reflection.h"
#include "tests/unit/PlacedBoxFixture.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using Labels = testing::PlacedChannel;

// The label of the nearest of `regions` random seeds in a 32^3 box, each
// region a random id (large and negative ones too).
struct VoronoiField {
    VoronoiField(std::mt19937& rng, int regions) : centres(size_t(regions)), ids(size_t(regions)) {
        for (int r = 0; r < regions; ++r) {
            centres[size_t(r)] = {int(rng() % 32), int(rng() % 32), int(rng() % 32)};
            ids[size_t(r)] = int32_t(rng() % 200000) - 100000;
        }
    }
    int32_t operator()(int X, int Y, int Z) const {
        size_t best = 0;
        int bestD = 1 << 30;
        for (size_t r = 0; r < centres.size(); ++r) {
            const auto& c = centres[r];
            const int d = (X - c[0]) * (X - c[0]) + (Y - c[1]) * (Y - c[1]) + (Z - c[2]) * (Z - c[2]);
            if (d < bestD) bestD = d, best = r;
        }
        return ids[best];
    }
    std::vector<std::array<int, 3>> centres;
    std::vector<int32_t> ids;
};

// Voronoi regions over the placed box (PlacedBoxFixture.h), every 97th
// brick (from the 6th) a tile of the first label.
Labels voronoi(uint32_t seed, int regions) {
    std::mt19937 rng(seed);
    const VoronoiField field(rng, regions);
    return testing::placedBox(rng, true, field, 97, 5, field.ids[0]);
}

// The same regions as a scan's import lays them out: each uniform 8^3
// block a tile (PlacedBoxFixture.h's placedBlockBox).
Labels tiledVoronoi(uint32_t seed, int regions) {
    std::mt19937 rng(seed);
    const VoronoiField field(rng, regions);
    return testing::placedBlockBox(rng, field);
}

// Each generation in the brick order its window coding walks (7: spatial,
// 17 and 18: raster blocks).
BrickOrder orderOf(int generation) { return generation == 1 ? BrickOrder::Spatial : BrickOrder::Raster; }

TEST(LabelCoder, LabelVolumesComeBackExactlyForAFractionOfTheNumericCost) {
    // 1,500 regions of about 22 voxels: more labels than generation 2's
    // list of 1,024 holds, so labels leave it and come back as new ones.
    for (const int generation : {1, 2, 3}) {
        for (int regions : {1, 12, 60, 1500}) {
            const Labels l = voronoi(uint32_t(regions), regions);
            const auto [lo, hi] = std::minmax_element(l.entries.begin(), l.entries.end());
            const BrickOrder order = orderOf(generation);
            const std::vector<uint8_t> bytes = encodePlacedLabels(l.entries, l.layout, l.places, order, *lo, *hi, generation);
            std::vector<int32_t> back(l.entries.size());
            decodePlacedLabels(bytes, l.layout, l.places, order, *lo, *hi, back, "labels", generation);
            EXPECT_EQ(back, l.entries) << regions << " regions, generation " << generation;
            IntCoderOptions o;
            o.minValue = *lo, o.maxValue = *hi;
            const size_t numeric = encodePlacedBrickValues(l.entries, l.layout, l.places, BrickOrder::Spatial, o).size();
            if (regions == 1) {
                EXPECT_LT(bytes.size(), 100u);  // one label: next to nothing
            } else if (regions < 1000) {
                EXPECT_LT(bytes.size() * 2, numeric) << regions << " regions: labels " << bytes.size() << ", numeric " << numeric;
            }
        }
    }
}

// Generation 2's move-to-front list through every case: a label volume of
// 2x2x2 cells, 2,000 labels cycling over the 4,096 cells, so that a cell's
// first voxel matches none of its neighbours and is coded by its rank in the
// list, at every rank up to the list's 1,024 and beyond (a label dropped
// from the list comes back as a new one).
TEST(LabelCoder, Generation2RanksEveryLabelItHasMet) {
    std::mt19937 rng(11);
    const Labels l = testing::placedBox(
        rng, true, [&](int X, int Y, int Z) { return int32_t(((X / 2) * 131 + (Y / 2) * 17 + (Z / 2) * 7) % 2000) - 1000; }, 0, 0, 0);
    const auto [lo, hi] = std::minmax_element(l.entries.begin(), l.entries.end());
    const std::vector<uint8_t> bytes = encodePlacedLabels(l.entries, l.layout, l.places, BrickOrder::Raster, *lo, *hi, 2);
    std::vector<int32_t> back(l.entries.size());
    decodePlacedLabels(bytes, l.layout, l.places, BrickOrder::Raster, *lo, *hi, back, "labels", 2);
    EXPECT_EQ(back, l.entries);
}

// Generation 3 on atlases whose uniform 8^3 blocks are tiles: every label
// comes back, from one region (all tiles) to 400 (few); generation 2 reads
// the same layout with its tiles as no neighbours.
TEST(LabelCoder, Generation3SeesTilesAsNeighbours) {
    for (int regions : {1, 5, 40, 400}) {
        const Labels l = tiledVoronoi(uint32_t(regions) + 100, regions);
        const size_t tiles = size_t(std::count(l.layout.begin(), l.layout.end(), uint64_t(0)));
        if (regions <= 5) {
            EXPECT_GT(tiles, 0u) << regions;
        }
        const auto [lo, hi] = std::minmax_element(l.entries.begin(), l.entries.end());
        for (const int generation : {2, 3}) {
            const std::vector<uint8_t> bytes = encodePlacedLabels(l.entries, l.layout, l.places, BrickOrder::Raster, *lo, *hi, generation);
            std::vector<int32_t> back(l.entries.size());
            decodePlacedLabels(bytes, l.layout, l.places, BrickOrder::Raster, *lo, *hi, back, "labels", generation);
            EXPECT_EQ(back, l.entries) << regions << " regions, " << tiles << " tiles, generation " << generation;
        }
    }
    // A tile not aligned to its size is refused, not walked.
    Labels bad = tiledVoronoi(1, 1);
    bad.places[0].x += 4;
    EXPECT_THROW(encodePlacedLabels(bad.entries, bad.layout, bad.places, BrickOrder::Raster, bad.entries[0], bad.entries[0], 3), Error);
}

TEST(LabelCoder, OutOfRangeLabelsAndCorruptStreamsAreRefused) {
    for (const int generation : {1, 2, 3}) {
        const Labels l = generation == 3 ? tiledVoronoi(3, 20) : voronoi(3, 20);
        const auto [lo, hi] = std::minmax_element(l.entries.begin(), l.entries.end());
        const BrickOrder order = orderOf(generation);
        EXPECT_THROW(encodePlacedLabels(l.entries, l.layout, l.places, order, *lo + 1, *hi, generation), Error);
        const std::vector<uint8_t> bytes = encodePlacedLabels(l.entries, l.layout, l.places, order, *lo, *hi, generation);
        std::vector<int32_t> back(l.entries.size());
        EXPECT_THROW(decodePlacedLabels(std::vector<uint8_t>(bytes.begin(), bytes.begin() + ptrdiff_t(bytes.size() / 2)), l.layout, l.places, order, *lo,
                                        *hi, back, "half", generation),
                     Error);
        std::mt19937 rng(4);
        for (int trial = 0; trial < 20; ++trial) {
            std::vector<uint8_t> garbage(bytes.size());
            for (auto& b : garbage) b = uint8_t(rng());
            try {
                decodePlacedLabels(garbage, l.layout, l.places, order, *lo, *hi, back, "garbage", generation);
                for (int32_t v : back) ASSERT_TRUE(v >= *lo && v <= *hi);
            } catch (const Error&) {
            }
        }
    }
}

TEST(LabelCoder, PredictedWindowsStoreLabelsAsCoding18) {
    const Labels l = voronoi(5, 30);
    std::vector<uint8_t> bytes(l.entries.size() * 4);
    std::memcpy(bytes.data(), l.entries.data(), bytes.size());
    const std::vector<uint8_t> windows = attributes::encodePredictedWindows(bytes, 4, l.layout, l.places);
    const attributes::WindowDirectory dir = attributes::readPredictedWindowDirectory(windows, 4, l.layout, "test");
    ASSERT_EQ(dir.windows.size(), 1u);
    EXPECT_EQ(windows[size_t(dir.windows[0].offset)], attributes::detail::kTiledLabelCoding);
    EXPECT_EQ(attributes::decodePredictedWindows(windows, 4, l.layout, "test", l.places), bytes);
    EXPECT_THROW(attributes::decodePredictedWindows(windows, 4, l.layout, "test", {}), Error);  // a label window needs its places
}

// One predicted window of `entries` int32 entries, stored as it is, with
// the raw bytes `raw` (coding byte, payload): the layout of FORMAT.md 8.1
// written out by hand, as a writer before codings 6 and 7 wrote it.
std::vector<uint8_t> oneWindowByHand(std::span<const uint8_t> raw, uint64_t entries) {
    std::vector<uint8_t> out;
    const auto put = [&](auto v) {
        const size_t at = out.size();
        out.resize(at + sizeof v);
        std::memcpy(out.data() + at, &v, sizeof v);
    };
    put(uint32_t(4)), put(entries), put(uint64_t(1) << 22), put(uint64_t(1));
    out.insert(out.end(), raw.begin(), raw.end());
    put(uint64_t(raw.size())), put(uint64_t(raw.size())), put(entries);
    return out;
}

// A window of `coding` holding `l`'s entries as label model `generation`
// codes them in `order`, written by hand as an older writer wrote it, and
// the entries' bytes.
std::pair<std::vector<uint8_t>, std::vector<uint8_t>> labelWindowByHand(const Labels& l, uint8_t coding, BrickOrder order, int generation) {
    std::vector<uint8_t> bytes(l.entries.size() * 4);
    std::memcpy(bytes.data(), l.entries.data(), bytes.size());
    std::vector<uint8_t> raw{coding};
    const std::vector<uint8_t> payload = attributes::encodeContextChannel(bytes, l.layout, l.places, true, order, kLatestIntModel, generation);
    raw.insert(raw.end(), payload.begin(), payload.end());
    return {raw, bytes};
}

// A window of coding 7 (label model generation 1, what files before coding
// 17 hold) still reads: written by hand, as that writer wrote it.
TEST(LabelCoder, WindowsOfLabelGeneration1StillRead) {
    const Labels l = voronoi(8, 40);
    auto [raw, bytes] = labelWindowByHand(l, attributes::detail::kSpatialLabelCoding, BrickOrder::Spatial, 1);
    EXPECT_EQ(attributes::decodePredictedWindows(oneWindowByHand(raw, l.entries.size()), 4, l.layout, "coding 7", l.places), bytes);
    // Read as coding 17, the same payload is another model: it must not give the entries back.
    raw[0] = attributes::detail::kShapedLabelCoding;
    try {
        EXPECT_NE(attributes::decodePredictedWindows(oneWindowByHand(raw, l.entries.size()), 4, l.layout, "misread", l.places), bytes);
    } catch (const Error&) {
    }
}

// A window of coding 17 (label model generation 2, what files of
// 2026-12-06 before coding 18 hold) still reads, tiles and all: written by
// hand, as that writer wrote it.
TEST(LabelCoder, WindowsOfLabelGeneration2StillRead) {
    const Labels l = tiledVoronoi(9, 30);
    const auto [raw, bytes] = labelWindowByHand(l, attributes::detail::kShapedLabelCoding, BrickOrder::Raster, 2);
    EXPECT_EQ(attributes::decodePredictedWindows(oneWindowByHand(raw, l.entries.size()), 4, l.layout, "coding 17", l.places), bytes);
}

// Windows of codings 3 and 4 (bricks in the layout's order, what files
// before codings 6 and 7 hold) still read, on a layout whose bricks come
// from the far corner, so that the two orders differ.
TEST(LabelCoder, WindowsInTheLayoutsBrickOrderStillRead) {
    const Labels l = testing::reversedBricks(voronoi(7, 12));
    std::vector<uint8_t> bytes(l.entries.size() * 4);
    std::memcpy(bytes.data(), l.entries.data(), bytes.size());
    for (const bool labels : {false, true}) {
        std::vector<uint8_t> raw{labels ? attributes::detail::kPlacedLabelCoding : attributes::detail::kPlacedContextCoding};
        const std::vector<uint8_t> payload = attributes::encodeContextChannel(bytes, l.layout, l.places, labels, BrickOrder::Attribute);
        raw.insert(raw.end(), payload.begin(), payload.end());
        EXPECT_EQ(attributes::decodePredictedWindows(oneWindowByHand(raw, l.entries.size()), 4, l.layout, "old", l.places), bytes) << "labels " << labels;
        // The same payload read in spatial order is another walk: it must not give the entries back.
        raw[0] = labels ? attributes::detail::kSpatialLabelCoding : attributes::detail::kSpatialContextCoding;
        try {
            EXPECT_NE(attributes::decodePredictedWindows(oneWindowByHand(raw, l.entries.size()), 4, l.layout, "misread", l.places), bytes);
        } catch (const Error&) {
        }
    }
}

} // namespace
} // namespace vdbdag::coding
