// The walk of a placed layout (BrickValueCoder.h: brick instances in
// attribute order, each with its corner and mirror) shared by the value
// coders that see neighbours across bricks (BrickValueCoder's coding 3,
// LabelCoder): brick by brick, each brick's voxels in spatial raster order
// (x fastest), in the layout's order or in spatial order (BrickOrder), each
// with its causal neighbours
//      this slice:  NW N NE        slice below:  PNW PN
//                   W  *                         PW  P
// (and, for a walk that asks for them, WW, NN and PP two voxels back along
// x, y and z, Reach::Far; and also the rest of the slice below, PE, PS,
// PNE, PSW, PSE, and NWW, NNE, NNW, NEE, Reach::Wide; and also WWW, WWWW,
// NWWW, NEEE, NNN, Reach::Widest; or only PE and PS, Reach::Ahead) wherever they were
// visited before in the same walk (in this brick or in any brick before it),
// and its entry: the rank of its stored bit (dag_access.h dagStoredBit). A
// tile (mask 0) is one entry; its place is its corner, with the log2 of its
// size in `mirror` (a tile has no mirror), which only a walk with tile
// neighbours reads (walkPlacedBricks' kTiles).
#pragma once


#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <deque>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "src/coding/BrickValueCoder.h"
#include "src/dag/Reflection.h"
#include "src/util/Error.h"

namespace vdbdag::coding::detail {

// A brick in spatial order: which voxels are visited, their values and the
// coder's record of each.
template <typename Rec>
struct PlacedBrick {
    PlacedBrick() {}  // values and records are read only where `done` says (no zeroing: a brick is 1-2 KB)
    uint64_t done = 0;
    int32_t value[64];
    Rec rec[64];
};

// Which neighbours beyond the near eight a walk finds (the header comment);
// Ahead: PE and PS alone (the label coder's generation 2). Listed after the
// others so that the integer coder's `>= Wide` tests keep their meaning.
enum class Reach { Near, Far, Wide, Widest, Ahead };
constexpr bool findsFar(Reach r) { return r == Reach::Far || r == Reach::Wide || r == Reach::Widest; }
constexpr bool findsWide(Reach r) { return r == Reach::Wide || r == Reach::Widest; }
constexpr bool findsAhead(Reach r) { return r == Reach::Ahead || findsWide(r); }  // PE, PS: the slice below, a row ahead

template <typename Rec>
struct PlacedNeighbours {
    enum Which { W, N, NW, NE, P, PW, PN, PNW, WW, NN, PP, PE, PS, PNE, PSW, PSE, NWW, NNE, NNW, NEE, WWW, WWWW, NWWW, NEEE, NNN, kCount };
    const PlacedBrick<Rec>* brick[kCount];
    int bit[kCount];
    bool has(Which k) const { return brick[k] != nullptr; }
    int32_t value(Which k) const { return brick[k]->value[bit[k]]; }
    const Rec& rec(Which k) const { return brick[k]->rec[bit[k]]; }
};

struct BrickKey {
    int32_t x, y, z;
    bool operator==(const BrickKey&) const = default;
};
// Bricks (or tiles) by their coordinates: open addressing with linear
// probing in one array of at least twice the keys' count, so a lookup is a
// hash and a probe or two in memory that is already near, where
// std::unordered_map chased a node per key (5 % of a level set's encode).
// Memory: 16 bytes per slot, 32-64 bytes per key.
class BrickIndex {
public:
    static constexpr uint32_t kNone = UINT32_MAX;
    explicit BrickIndex(size_t keys) {
        size_t capacity = 16;
        while (capacity < 2 * keys) capacity *= 2;
        slots_.assign(capacity, Slot{});
        mask_ = capacity - 1;
    }
    // Adds key -> value (not kNone); false when the key is there already.
    bool insert(const BrickKey& key, uint32_t value) {
        for (size_t i = hash(key);; i = (i + 1) & mask_) {
            Slot& s = slots_[i];
            if (s.value == kNone) {
                s.key = key, s.value = value;
                return true;
            }
            if (s.key == key) return false;
        }
    }
    uint32_t find(const BrickKey& key) const {
        for (size_t i = hash(key);; i = (i + 1) & mask_) {
            const Slot& s = slots_[i];
            if (s.value == kNone || s.key == key) return s.value;
        }
    }

private:
    struct Slot {
        BrickKey key{};
        uint32_t value = kNone;
    };
    size_t hash(const BrickKey& k) const {
        uint64_t h = uint64_t(uint32_t(k.x)) * 0x9E3779B97F4A7C15ull;
        h ^= uint64_t(uint32_t(k.y)) * 0xC2B2AE3D27D4EB4Full + (h >> 29);
        h ^= uint64_t(uint32_t(k.z)) * 0x165667B19E3779F9ull + (h >> 32);
        return size_t(h ^ (h >> 31)) & mask_;
    }
    std::vector<Slot> slots_;
    size_t mask_ = 0;
};

// Whether corner p comes before corner q in Morton order (z's bit above
// y's above x's at each level, coordinates as unsigned after flipping the
// sign bit): the axis whose coordinates differ in the highest bit decides.
// Morton order is monotone: a corner below another on every axis comes
// first, so W, N, P and their diagonals towards the origin always precede.
inline bool mortonLess(const BrickPlace& p, const BrickPlace& q) {
    const uint32_t a[3] = {uint32_t(p.z) ^ 0x80000000u, uint32_t(p.y) ^ 0x80000000u, uint32_t(p.x) ^ 0x80000000u};
    const uint32_t b[3] = {uint32_t(q.z) ^ 0x80000000u, uint32_t(q.y) ^ 0x80000000u, uint32_t(q.x) ^ 0x80000000u};
    int axis = 0;
    uint32_t highest = a[0] ^ b[0];
    for (int k = 1; k < 3; ++k) {
        const uint32_t d = a[k] ^ b[k];
        if (highest < d && highest < (highest ^ d)) axis = k, highest = d;  // d's top bit is above highest's
    }
    return a[axis] < b[axis];
}

// BrickOrder::Raster's blocks: 32^3 voxels (8^3 bricks). Against whole-
// window raster order (tooth 602,768 bytes, FLAIR 737,031, cthead
// 1,446,456) and Morton order (603,265, 734,531, 1,406,174): 602,894,
// 734,571, 1,404,560. A fit adapts to what it saw last, so the bricks of a
// small region together code smaller than a window-wide sweep.
inline constexpr int kRasterBlockShift = 5;

// The instances' visiting order: the layout's own (BrickOrder::Attribute),
// or (BrickOrder::Spatial, Raster) its tiles in layout order, then its
// bricks in the Morton order of their corners (Spatial), or of their
// 32^3 blocks and in (z, y, x) order inside a block (Raster). `first[b]`: instance b's first entry.
// Throws vdbdag::Error when the layout holds more than `entries` entries.
inline std::vector<uint32_t> placedVisitOrder(std::span<const uint64_t> layout, std::span<const BrickPlace> places, uint64_t entries, BrickOrder order,
                                              std::vector<uint64_t>& first) {
    if (layout.size() > UINT32_MAX) throw Error("more than 2^32 brick instances in one call");
    first.resize(layout.size());
    uint64_t e = 0;
    for (size_t b = 0; b < layout.size(); ++b) {
        first[b] = e;
        e += layout[b] ? uint64_t(std::popcount(layout[b])) : 1;
        if (e > entries) throw Error("the layout holds more entries than the channel");
    }
    std::vector<uint32_t> visit(layout.size());
    for (size_t b = 0; b < layout.size(); ++b) visit[b] = uint32_t(b);
    if (order == BrickOrder::Spatial)
        std::stable_sort(visit.begin(), visit.end(), [&](uint32_t a, uint32_t b) {
            const bool tileA = layout[a] == 0, tileB = layout[b] == 0;
            if (tileA || tileB) return tileA && !tileB;
            return mortonLess(places[a], places[b]);
        });
    if (order == BrickOrder::Raster)
        std::stable_sort(visit.begin(), visit.end(), [&](uint32_t a, uint32_t b) {
            const bool tileA = layout[a] == 0, tileB = layout[b] == 0;
            if (tileA || tileB) return tileA && !tileB;
            const BrickPlace& p = places[a];
            const BrickPlace& q = places[b];
            const BrickPlace bp{p.x >> kRasterBlockShift, p.y >> kRasterBlockShift, p.z >> kRasterBlockShift, 0};
            const BrickPlace bq{q.x >> kRasterBlockShift, q.y >> kRasterBlockShift, q.z >> kRasterBlockShift, 0};
            if (bp.x != bq.x || bp.y != bq.y || bp.z != bq.z) return mortonLess(bp, bq);
            return std::tie(p.z, p.y, p.x) < std::tie(q.z, q.y, q.x);
        });
    return visit;
}

// With kTiles (label generation 3, the integers' coding 19), tiles are
// neighbours too: a tile up to kNeighbourTileLog2 wide is visited first
// (spatial orders), given the values of the tiles of its size W, N and P
// of it visited before it (TileNeighbours), and returns its value; a voxel
// whose neighbour lies in such a tile then sees the tile's value there (its
// record Rec{}), where without kTiles it sees nothing. A larger tile (a
// .vdb's 128^3) is no neighbour: it would stand for thousands of bricks.
inline constexpr unsigned kNeighbourTileLog2 = 5;
struct TileNeighbours {
    enum Which { W, N, P, kCount };
    std::array<bool, kCount> has{};
    std::array<int32_t, kCount> value{};
};

// tile(entry) (kTiles: tile(entry, TileNeighbours) -> the tile's value);
// voxel(neighbours, entry, value&, rec&) sets the voxel's value (read or
// decoded) and its record, visiting the instances in `order`; `kReach`
// says which neighbours beyond the near eight it finds.
// Throws vdbdag::Error when the layout, its places and `entries` disagree.
//
// Memory: a brick's values and records are kept only while a brick visited
// later may still read them (one of the bricks it lies beside in the
// directions the walk looks back: counted before the walk, the count taken
// down as each is visited); then its slot is reused. The walk reads the
// same neighbours either way.
template <typename Rec, Reach kReach = Reach::Near, bool kTiles = false, typename Tile, typename Voxel>
void walkPlacedBricks(std::span<const uint64_t> layout, std::span<const BrickPlace> places, uint64_t entries, BrickOrder order, Tile&& tile,
                      Voxel&& voxel) {
    if (places.size() != layout.size()) throw Error("the layout has " + std::to_string(layout.size()) + " bricks, their places " + std::to_string(places.size()));
    std::vector<uint64_t> first;
    const std::vector<uint32_t> visit = placedVisitOrder(layout, places, entries, order, first);
    // Every brick by its coordinates (index / 4), and its rank in the walk.
    constexpr uint32_t kNone = BrickIndex::kNone;
    size_t bricks = 0;
    for (const uint64_t mask : layout) bricks += mask != 0;
    BrickIndex brickAt(bricks);
    std::vector<uint32_t> rank(layout.size(), kNone);
    for (size_t r = 0; r < visit.size(); ++r) {
        const uint32_t b = visit[r];
        if (layout[b] == 0) continue;
        const BrickPlace& place = places[b];
        if ((place.x | place.y | place.z) & 3 || place.mirror > 7) throw Error("brick " + std::to_string(b) + " has no brick's place");
        if (!brickAt.insert(BrickKey{place.x >> 2, place.y >> 2, place.z >> 2}, b)) throw Error("two bricks at the same place");
        rank[b] = uint32_t(r);
    }
    // kTiles: the neighbour tiles by size (8, 16, 32) and corner (in
    // bricks): memory per tile, not per voxel, so a window of forged tiles
    // costs what its layout does.
    constexpr unsigned kSmallestTileLog2 = 3, kTileSizes = kNeighbourTileLog2 - kSmallestTileLog2 + 1;
    static_assert(kTileSizes == 3);
    std::array<BrickIndex, kTileSizes> tilesBySize{BrickIndex(0), BrickIndex(0), BrickIndex(0)};
    std::vector<int32_t> tileValue;
    std::vector<uint8_t> tileDone;
    if constexpr (kTiles) {
        if (order == BrickOrder::Attribute) throw Error("internal error: tile neighbours need a spatial order");
        tileValue.assign(layout.size(), 0);
        tileDone.assign(layout.size(), 0);
        std::array<size_t, kTileSizes> tiles{};
        for (size_t b = 0; b < layout.size(); ++b)
            if (layout[b] == 0 && places[b].mirror >= kSmallestTileLog2 && places[b].mirror <= kNeighbourTileLog2) ++tiles[places[b].mirror - kSmallestTileLog2];
        for (unsigned s = 0; s < kTileSizes; ++s) tilesBySize[s] = BrickIndex(tiles[s]);
        for (size_t b = 0; b < layout.size(); ++b) {
            const BrickPlace& t = places[b];
            if (layout[b] != 0 || t.mirror < kSmallestTileLog2 || t.mirror > kNeighbourTileLog2) continue;
            if ((t.x | t.y | t.z) & ((int32_t(1) << t.mirror) - 1)) throw Error("tile " + std::to_string(b) + " is not aligned to its size");
            if (!tilesBySize[t.mirror - kSmallestTileLog2].insert(BrickKey{t.x >> 2, t.y >> 2, t.z >> 2}, uint32_t(b)))
                throw Error("two tiles at the same place");
        }
    }
    // The visited neighbour tile holding brick cell `key`, or kNone.
    const auto tileHolding = [&](const BrickKey& key) -> uint32_t {
        for (unsigned s = 0; s < kTileSizes; ++s) {
            const int32_t cells = ~((int32_t(1) << (s + kSmallestTileLog2 - 2)) - 1);  // a tile's corner, in bricks
            const uint32_t t = tilesBySize[s].find(BrickKey{key.x & cells, key.y & cells, key.z & cells});
            if (t != kNone) return tileDone[t] ? t : kNone;
        }
        return kNone;
    };
    // A visited tile beside the brick being visited, as a brick every voxel
    // of which holds its value (records Rec{}): one scratch brick per
    // direction, filled when a brick is visited.
    std::array<PlacedBrick<Rec>, kTiles ? 26 : 0> tileScratch;
    const auto tileBrick = [&](const BrickKey& key, size_t slot) -> const PlacedBrick<Rec>* {
        if constexpr (kTiles) {
            const uint32_t t = tileHolding(key);
            if (t == kNone) return nullptr;
            PlacedBrick<Rec>& u = tileScratch[slot];
            u.done = ~uint64_t(0);
            std::fill(std::begin(u.value), std::end(u.value), tileValue[t]);
            std::fill(std::begin(u.rec), std::end(u.rec), Rec{});
            return &u;
        } else {
            (void)key, (void)slot;
            return nullptr;
        }
    };
    // The bricks around that hold causal neighbours: dx in -1..1, dy in
    // -1..0 (-1..1 for Reach::Wide and Widest, whose PS lies a row ahead),
    // dz in -1..0; `lookBack[k]` is offset k, ((dx+1), (dy+1), (dz+1)).
    constexpr int kDyHigh = findsAhead(kReach) ? 1 : 0;
    std::vector<std::array<int, 3>> lookBack;
    for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= kDyHigh; ++dy)
            for (int dz = -1; dz <= 0; ++dz)
                if (dx || dy || dz) lookBack.push_back({dx, dy, dz});
    const auto brickBeside = [&](uint32_t b, const std::array<int, 3>& d) {
        return brickAt.find(BrickKey{(places[b].x >> 2) + d[0], (places[b].y >> 2) + d[1], (places[b].z >> 2) + d[2]});
    };
    // Readers still to come of each brick: the later bricks it lies beside.
    std::vector<uint8_t> readers(layout.size(), 0);
    for (const uint32_t b : visit) {
        if (layout[b] == 0) continue;
        for (const auto& d : lookBack) {
            const uint32_t n = brickBeside(b, d);
            if (n != kNone && rank[n] < rank[b]) ++readers[n];
        }
    }
    std::deque<PlacedBrick<Rec>> pool;  // kept bricks (a deque: `around` points into it)
    std::vector<PlacedBrick<Rec>*> freeSlots;
    std::vector<PlacedBrick<Rec>*> kept(layout.size(), nullptr);
    const auto release = [&](uint32_t b) {
        freeSlots.push_back(kept[b]);
        kept[b] = nullptr;
    };
    uint64_t total = 0;
    for (const uint32_t b : visit) {
        const uint64_t mask = layout[b];
        const uint64_t e = first[b];  // the instance's first entry
        if (mask == 0) {
            if constexpr (kTiles) {
                const BrickPlace& t = places[b];
                TileNeighbours tn;
                if (t.mirror >= kSmallestTileLog2 && t.mirror <= kNeighbourTileLog2) {  // a neighbour tile itself: its neighbours of its size
                    const auto& same = tilesBySize[t.mirror - kSmallestTileLog2];
                    const int32_t cells = int32_t(1) << (t.mirror - 2);
                    const BrickKey keys[TileNeighbours::kCount] = {
                        {(t.x >> 2) - cells, t.y >> 2, t.z >> 2}, {t.x >> 2, (t.y >> 2) - cells, t.z >> 2}, {t.x >> 2, t.y >> 2, (t.z >> 2) - cells}};
                    for (int k = 0; k < TileNeighbours::kCount; ++k) {
                        const uint32_t u = same.find(keys[k]);
                        if (u == kNone || !tileDone[u]) continue;
                        tn.has[size_t(k)] = true;
                        tn.value[size_t(k)] = tileValue[u];
                    }
                }
                tileValue[b] = tile(e, tn);
                tileDone[b] = 1;
            } else {
                tile(e);
            }
            ++total;
            continue;
        }
        const BrickPlace& place = places[b];
        PlacedBrick<Rec>* slot;
        if (freeSlots.empty()) slot = &pool.emplace_back();
        else slot = freeSlots.back(), freeSlots.pop_back();
        slot->done = 0;
        kept[b] = slot;
        PlacedBrick<Rec>& self = *slot;
        const PlacedBrick<Rec>* around[3][3][2] = {};
        uint32_t beside[26];
        for (size_t k = 0; k < lookBack.size(); ++k) {
            const auto& d = lookBack[k];
            beside[k] = brickBeside(b, d);
            around[d[0] + 1][d[1] + 1][d[2] + 1] =
                beside[k] != kNone ? kept[beside[k]]  // null: not visited yet
                                   : tileBrick(BrickKey{(place.x >> 2) + d[0], (place.y >> 2) + d[1], (place.z >> 2) + d[2]}, k);
        }
        around[1][1][1] = &self;
        const uint64_t spatial = dag::reflectBrick(mask, place.mirror);
        PlacedNeighbours<Rec> n;
        // A neighbour's brick and bit, or null when it is not visited yet.
        const auto at = [&](typename PlacedNeighbours<Rec>::Which k, int x, int y, int z) {
            const int ox = x < 0 ? -1 : x > 3 ? 1 : 0, oy = y < 0 ? -1 : y > 3 ? 1 : 0, oz = z < 0 ? -1 : 0;  // x in -4..6, y in -3..4, z in -2..3
            const PlacedBrick<Rec>* t = around[ox + 1][oy + 1][oz + 1];
            n.bit[k] = (x & 3) + 4 * (y & 3) + 16 * (z & 3);
            n.brick[k] = t && (t->done >> n.bit[k] & 1) ? t : nullptr;
        };
        using Nb = PlacedNeighbours<Rec>;
        for (uint64_t bits = spatial; bits; bits &= bits - 1) {
            const int p = std::countr_zero(bits), x = p & 3, y = (p >> 2) & 3, z = p >> 4;
            at(Nb::W, x - 1, y, z), at(Nb::N, x, y - 1, z), at(Nb::NW, x - 1, y - 1, z), at(Nb::NE, x + 1, y - 1, z);
            at(Nb::P, x, y, z - 1), at(Nb::PW, x - 1, y, z - 1), at(Nb::PN, x, y - 1, z - 1), at(Nb::PNW, x - 1, y - 1, z - 1);
            if constexpr (findsFar(kReach)) at(Nb::WW, x - 2, y, z), at(Nb::NN, x, y - 2, z), at(Nb::PP, x, y, z - 2);
            if constexpr (findsAhead(kReach)) at(Nb::PE, x + 1, y, z - 1), at(Nb::PS, x, y + 1, z - 1);
            if constexpr (findsWide(kReach)) {
                at(Nb::PNE, x + 1, y - 1, z - 1), at(Nb::PSW, x - 1, y + 1, z - 1);
                at(Nb::PSE, x + 1, y + 1, z - 1), at(Nb::NWW, x - 2, y - 1, z), at(Nb::NNE, x + 1, y - 2, z), at(Nb::NNW, x - 1, y - 2, z);
                at(Nb::NEE, x + 2, y - 1, z);
            }
            if constexpr (kReach == Reach::Widest)
                at(Nb::WWW, x - 3, y, z), at(Nb::WWWW, x - 4, y, z), at(Nb::NWWW, x - 3, y - 1, z), at(Nb::NEEE, x + 3, y - 1, z), at(Nb::NNN, x, y - 3, z);
            const unsigned stored = access::dagStoredBit(unsigned(x), unsigned(y), unsigned(z), place.mirror);
            voxel(n, e + uint64_t(std::popcount(mask & ((uint64_t(1) << stored) - 1))), self.value[p], self.rec[p]);
            self.done |= uint64_t(1) << p;
        }
        total += uint64_t(std::popcount(mask));
        // This brick has read the bricks before it beside it: those no
        // later brick reads are released, and so is this one if none will.
        for (size_t k = 0; k < lookBack.size(); ++k)
            if (beside[k] != kNone && rank[beside[k]] < rank[b] && --readers[beside[k]] == 0) release(beside[k]);
        if (readers[b] == 0) release(b);
    }
    if (total != entries) throw Error("the layout holds " + std::to_string(total) + " entries, the channel " + std::to_string(entries));
}

} // namespace vdbdag::coding::detail
