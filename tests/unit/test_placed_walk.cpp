// The placed walk (coding/PlacedWalk.h) against a brute-force reference:
// on random layouts of bricks (random masks, mirrors, tiles, places with
// gaps) in every visiting order, every neighbour the walk reports for a
// voxel is the voxel at that offset, visited before it, with the value the
// walk set there; and every such voxel within the walk's reach is
// reported. The walk releases a brick's slot once no later brick reads it,
// so a slot reused too early shows here as a wrong value.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "src/coding/PlacedWalk.h"

using namespace vdbdag;
using namespace vdbdag::coding;
using Nb = detail::PlacedNeighbours<int>;

namespace {

using Coord = std::array<int, 3>;

// Offsets of the walk's neighbours (PlacedWalk.h), Reach::Widest.
const std::array<std::pair<Nb::Which, Coord>, Nb::kCount> kOffsets{{
    {Nb::W, {-1, 0, 0}},    {Nb::N, {0, -1, 0}},    {Nb::NW, {-1, -1, 0}},  {Nb::NE, {1, -1, 0}},   {Nb::P, {0, 0, -1}},
    {Nb::PW, {-1, 0, -1}},  {Nb::PN, {0, -1, -1}},  {Nb::PNW, {-1, -1, -1}}, {Nb::WW, {-2, 0, 0}},  {Nb::NN, {0, -2, 0}},
    {Nb::PP, {0, 0, -2}},   {Nb::PE, {1, 0, -1}},   {Nb::PS, {0, 1, -1}},   {Nb::PNE, {1, -1, -1}}, {Nb::PSW, {-1, 1, -1}},
    {Nb::PSE, {1, 1, -1}},  {Nb::NWW, {-2, -1, 0}}, {Nb::NNE, {1, -2, 0}},  {Nb::NNW, {-1, -2, 0}}, {Nb::NEE, {2, -1, 0}},
    {Nb::WWW, {-3, 0, 0}},  {Nb::WWWW, {-4, 0, 0}}, {Nb::NWWW, {-3, -1, 0}}, {Nb::NEEE, {3, -1, 0}}, {Nb::NNN, {0, -3, 0}},
}};

struct Layout {
    std::vector<uint64_t> masks;
    std::vector<BrickPlace> places;
    uint64_t entries = 0;
};

Layout randomLayout(std::mt19937_64& rng, int side) {
    Layout l;
    for (int z = 0; z < side; ++z)
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                if (rng() % 3 == 0) continue;  // gaps: neighbours that are not there
                uint64_t mask = rng() & rng();
                if (rng() % 4 == 0) mask = ~uint64_t(0);
                if (!mask) mask = 1;
                l.masks.push_back(mask);
                l.places.push_back({x * 4, y * 4, z * 4, uint8_t(rng() % 8)});
                if (rng() % 10 == 0) {  // a tile: one entry, no place
                    l.masks.push_back(0);
                    l.places.push_back({0, 0, 0, 0});
                }
            }
    // The layout's own order is the attribute order: shuffle it.
    std::vector<size_t> order(l.masks.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    Layout shuffled;
    for (size_t i : order) {
        shuffled.masks.push_back(l.masks[i]);
        shuffled.places.push_back(l.places[i]);
        shuffled.entries += l.masks[i] ? uint64_t(std::popcount(l.masks[i])) : 1;
    }
    return shuffled;
}

} // namespace

TEST(PlacedWalk, NeighboursAreTheVoxelsVisitedBeforeWithTheirValues) {
    std::mt19937_64 rng(41);
    for (int round = 0; round < 6; ++round) {
        const Layout l = randomLayout(rng, 4 + round % 3);
        for (const BrickOrder order : {BrickOrder::Attribute, BrickOrder::Spatial, BrickOrder::Raster}) {
            SCOPED_TRACE(::testing::Message() << "round " << round << " order " << int(order));
            // Each entry's voxel (brute force: brick instance, stored bit, mirror).
            std::vector<Coord> voxelOf(l.entries);
            std::vector<bool> tileEntry(l.entries, false);
            uint64_t e = 0;
            for (size_t b = 0; b < l.masks.size(); ++b) {
                if (l.masks[b] == 0) {
                    tileEntry[e++] = true;
                    continue;
                }
                for (uint64_t bits = l.masks[b]; bits; bits &= bits - 1) {
                    const int stored = std::countr_zero(bits);
                    int x = stored & 3, y = (stored >> 2) & 3, z = stored >> 4;
                    const unsigned m = l.places[b].mirror;
                    if (m & 1u) x = 3 - x;
                    if (m & 2u) y = 3 - y;
                    if (m & 4u) z = 3 - z;
                    voxelOf[e++] = {l.places[b].x + x, l.places[b].y + y, l.places[b].z + z};
                }
            }
            std::map<Coord, uint64_t> entryAt;
            for (uint64_t i = 0; i < l.entries; ++i)
                if (!tileEntry[i]) entryAt[voxelOf[i]] = i;
            std::vector<int> visitedAt(l.entries, -1);  // the walk's step at which each entry was visited
            int step = 0;
            uint64_t checked = 0;
            detail::walkPlacedBricks<int, detail::Reach::Widest>(
                l.masks, l.places, l.entries, order, [&](uint64_t entry) { visitedAt[entry] = step++; },
                [&](const Nb& nb, uint64_t entry, int32_t& value, int& rec) {
                    ASSERT_FALSE(tileEntry[entry]);
                    const Coord c = voxelOf[entry];
                    for (const auto& [which, d] : kOffsets) {
                        const Coord at{c[0] + d[0], c[1] + d[1], c[2] + d[2]};
                        const auto it = entryAt.find(at);
                        const bool before = it != entryAt.end() && visitedAt[it->second] >= 0;
                        ASSERT_EQ(nb.has(which), before) << "neighbour " << int(which) << " of entry " << entry;
                        if (before) {
                            ASSERT_EQ(nb.value(which), int32_t(it->second) * 3 + 1) << "neighbour " << int(which) << " of entry " << entry;
                            ASSERT_EQ(nb.rec(which), int(it->second) ^ 0x5A5A) << "neighbour " << int(which);
                            ++checked;
                        }
                    }
                    value = int32_t(entry) * 3 + 1;
                    rec = int(entry) ^ 0x5A5A;
                    visitedAt[entry] = step++;
                });
            for (uint64_t i = 0; i < l.entries; ++i) ASSERT_GE(visitedAt[i], 0) << "entry " << i << " never visited";
            EXPECT_GT(checked, l.entries) << "the layouts should give many neighbours";
        }
    }
}
