// See BrickValueCoder.h. One template walks the entries for both
// directions, as IntVolumeCoder.cpp does.
#include "src/coding/BrickValueCoder.h"

#include <array>
#include <bit>
#include <unordered_map>
#include <memory>

#include "src/coding/CodingLoop.h"
#include "src/coding/SamplePredictor.h"
#include "src/dag/Reflection.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using namespace detail;

// `step(context, signs, prediction, entry)` returns the reconstructed entry.
template <typename Step>
void walk(std::span<const uint64_t> layout, uint64_t entries, const IntCoderOptions& options, Models& models, Step&& step) {
    int64_t value[64];
    SampleRecord rec[64];
    int64_t last = 0;         // the previous entry in attribute order
    SampleRecord lastRec{};   // and its record
    uint64_t e = 0;
    const auto code = [&](Neighbourhood& n) {
        const Prediction pr = predict(n, options.minValue, options.maxValue, models);
        const int64_t v = step(*pr.ctx, pr.signs, pr.value, e++);
        SampleRecord r;
        learn(pr, v, r);
        last = v;
        lastRec = r;
        return r;
    };
    for (const uint64_t mask : layout) {
        if (mask == 0) {  // a tile: one entry, no neighbours
            if (e >= entries) throw Error("the layout holds more entries than the channel");
            Neighbourhood n;
            n.W = n.N = n.NW = n.NE = n.P = n.PW = n.PN = n.PNW = last;
            n.rW = &lastRec;
            code(n);
            continue;
        }
        if (e + uint64_t(std::popcount(mask)) > entries) throw Error("the layout holds more entries than the channel");
        for (uint64_t bits = mask; bits; bits &= bits - 1) {
            const unsigned i = unsigned(std::countr_zero(bits));
            const unsigned x = i & 3u, y = (i >> 2) & 3u, z = i >> 4;
            const auto has = [&](bool inside, unsigned j) { return inside && ((mask >> j) & 1u); };
            const bool hx = has(x > 0, i - 1), hy = has(y > 0, i - 4), hz = has(z > 0, i - 16);
            const bool hnw = has(x > 0 && y > 0, i - 5), hne = has(x < 3 && y > 0, i - 3);
            Neighbourhood n;
            n.W = hx ? value[i - 1] : hy ? value[i - 4] : hz ? value[i - 16] : last;
            n.N = hy ? value[i - 4] : n.W;
            n.NW = hnw ? value[i - 5] : n.N;
            n.NE = hne ? value[i - 3] : n.N;
            if (hz) {
                n.P = value[i - 16];
                n.PW = has(x > 0, i - 17) ? value[i - 17] : n.P;
                n.PN = has(y > 0, i - 20) ? value[i - 20] : n.PW;
                n.PNW = has(x > 0 && y > 0, i - 21) ? value[i - 21] : n.PN;
            } else {
                n.P = med(n.W, n.N, n.NW), n.PW = n.W, n.PN = n.N, n.PNW = n.NW;
            }
            n.rW = hx ? &rec[i - 1] : (!hy && !hz) ? &lastRec : nullptr;
            n.rN = hy ? &rec[i - 4] : nullptr;
            n.rP = hz ? &rec[i - 16] : nullptr;
            const auto add = [&](bool present, unsigned j, unsigned times) {
                if (!present) return;
                for (size_t k = 0; k < size_t(kPredictors); ++k) n.errorsAbove[k] += times * uint64_t(rec[j].err[k]);
                n.residualsAbove += times * uint64_t(rec[j].residual);
            };
            add(hy, i - 4, 2), add(hz, i - 16, 2), add(hne, i - 3, 1), add(hnw, i - 5, 1);
            add(has(z > 0 && x > 0, i - 17), i - 17, 1), add(has(z > 0 && y > 0, i - 20), i - 20, 1);
            rec[i] = code(n);
            value[i] = last;
        }
    }
    if (e != entries) throw Error("the layout holds " + std::to_string(e) + " entries, the channel " + std::to_string(entries));
}

// What a coded voxel keeps for its neighbours, compactly (a window holds
// every brick it has coded): errors and residual saturated at 2^16 - 1.
struct CompactRecord {
    std::array<uint16_t, kPredictors> err{};
    uint16_t residual = 0;
    int8_t sign = 0;
    SampleRecord expand() const {
        SampleRecord r;
        for (size_t k = 0; k < size_t(kPredictors); ++k) r.err[k] = err[k];
        r.residual = residual, r.sign = sign;
        return r;
    }
    static CompactRecord of(const SampleRecord& r) {
        CompactRecord c;
        for (size_t k = 0; k < size_t(kPredictors); ++k) c.err[k] = uint16_t(std::min<uint32_t>(r.err[k], 65535));
        c.residual = uint16_t(std::min<uint32_t>(r.residual, 65535)), c.sign = r.sign;
        return c;
    }
};

// A brick in spatial order: which voxels are coded, their values and records.
struct PlacedBrick {
    uint64_t done = 0;
    int32_t value[64];
    CompactRecord rec[64];
};

struct BrickKey {
    int32_t x, y, z;
    bool operator==(const BrickKey&) const = default;
};
struct BrickKeyHash {
    size_t operator()(const BrickKey& k) const {
        uint64_t h = uint64_t(uint32_t(k.x)) * 0x9E3779B97F4A7C15ull;
        h ^= uint64_t(uint32_t(k.y)) * 0xC2B2AE3D27D4EB4Full + (h >> 29);
        h ^= uint64_t(uint32_t(k.z)) * 0x165667B19E3779F9ull + (h >> 32);
        return size_t(h);
    }
};

template <typename Step>
void walkPlaced(std::span<const uint64_t> layout, std::span<const BrickPlace> places, uint64_t entries, const IntCoderOptions& options, Models& models,
                Step&& step) {
    if (places.size() != layout.size()) throw Error("the layout has " + std::to_string(layout.size()) + " bricks, their places " + std::to_string(places.size()));
    // Brick coordinates (index / 4) -> index in `bricks`.
    const auto key = [](int64_t x, int64_t y, int64_t z) { return BrickKey{int32_t(x), int32_t(y), int32_t(z)}; };
    std::unordered_map<BrickKey, uint32_t, BrickKeyHash> slots;
    slots.reserve(layout.size());
    std::vector<PlacedBrick> bricks;
    bricks.reserve(layout.size());  // `around` points into it
    int64_t last = 0;
    SampleRecord lastRec{};
    uint64_t e = 0;  // the first entry of the current instance
    for (size_t b = 0; b < layout.size(); ++b) {
        const uint64_t mask = layout[b];
        if (mask == 0) {  // a tile: one entry, no neighbours
            if (e >= entries) throw Error("the layout holds more entries than the channel");
            Neighbourhood n;
            n.W = n.N = n.NW = n.NE = n.P = n.PW = n.PN = n.PNW = last;
            n.rW = &lastRec;
            const Prediction pr = predict(n, options.minValue, options.maxValue, models);
            last = step(*pr.ctx, pr.signs, pr.value, e++);
            learn(pr, last, lastRec);
            continue;
        }
        const BrickPlace& place = places[b];
        if ((place.x | place.y | place.z) & 3 || place.mirror > 7) throw Error("brick " + std::to_string(b) + " has no brick's place");
        if (e + uint64_t(std::popcount(mask)) > entries) throw Error("the layout holds more entries than the channel");
        const std::array<int64_t, 3> at{place.x >> 2, place.y >> 2, place.z >> 2};
        if (!slots.emplace(key(at[0], at[1], at[2]), uint32_t(bricks.size())).second) throw Error("two bricks at the same place");
        bricks.emplace_back();
        PlacedBrick& self = bricks.back();
        // The bricks around that hold causal neighbours: dx in -1..1, dy and dz in -1..0.
        const PlacedBrick* around[3][2][2];
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 0; ++dy)
                for (int dz = -1; dz <= 0; ++dz) {
                    const auto it = slots.find(key(at[0] + dx, at[1] + dy, at[2] + dz));
                    around[dx + 1][dy + 1][dz + 1] = (dx == 0 && dy == 0 && dz == 0) ? &self : it == slots.end() ? nullptr : &bricks[it->second];
                }
        const uint64_t spatial = dag::reflectBrick(mask, place.mirror);
        // A neighbour's brick and bit, or null when it is not coded yet.
        const auto at3 = [&](int x, int y, int z, int& bit) -> const PlacedBrick* {
            const int ox = x < 0 ? -1 : x > 3 ? 1 : 0, oy = y < 0 ? -1 : 0, oz = z < 0 ? -1 : 0;
            const PlacedBrick* t = around[ox + 1][oy + 1][oz + 1];
            bit = (x & 3) + 4 * (y & 3) + 16 * (z & 3);
            return t && (t->done >> bit & 1) ? t : nullptr;
        };
        for (uint64_t bits = spatial; bits; bits &= bits - 1) {
            const int p = std::countr_zero(bits), x = p & 3, y = (p >> 2) & 3, z = p >> 4;
            int bW, bN, bNW, bNE, bP, bPW, bPN, bPNW;
            const PlacedBrick *tW = at3(x - 1, y, z, bW), *tN = at3(x, y - 1, z, bN), *tNW = at3(x - 1, y - 1, z, bNW), *tNE = at3(x + 1, y - 1, z, bNE);
            const PlacedBrick *tP = at3(x, y, z - 1, bP), *tPW = at3(x - 1, y, z - 1, bPW), *tPN = at3(x, y - 1, z - 1, bPN),
                              *tPNW = at3(x - 1, y - 1, z - 1, bPNW);
            Neighbourhood n;
            n.W = tW ? tW->value[bW] : tN ? tN->value[bN] : tP ? tP->value[bP] : last;
            n.N = tN ? tN->value[bN] : n.W;
            n.NW = tNW ? tNW->value[bNW] : n.N;
            n.NE = tNE ? tNE->value[bNE] : n.N;
            if (tP) {
                n.P = tP->value[bP];
                n.PW = tPW ? tPW->value[bPW] : n.P;
                n.PN = tPN ? tPN->value[bPN] : n.PW;
                n.PNW = tPNW ? tPNW->value[bPNW] : n.PN;
            } else {
                n.P = med(n.W, n.N, n.NW), n.PW = n.W, n.PN = n.N, n.PNW = n.NW;
            }
            SampleRecord rW, rN, rP;
            if (tW) rW = tW->rec[bW].expand();
            if (tN) rN = tN->rec[bN].expand();
            if (tP) rP = tP->rec[bP].expand();
            n.rW = tW ? &rW : (!tN && !tP) ? &lastRec : nullptr;
            n.rN = tN ? &rN : nullptr;
            n.rP = tP ? &rP : nullptr;
            const auto add = [&](const PlacedBrick* t, int bit, unsigned times) {
                if (!t) return;
                for (size_t k = 0; k < size_t(kPredictors); ++k) n.errorsAbove[k] += times * uint64_t(t->rec[bit].err[k]);
                n.residualsAbove += times * uint64_t(t->rec[bit].residual);
            };
            add(tN, bN, 2), add(tP, bP, 2), add(tNE, bNE, 1), add(tNW, bNW, 1), add(tPW, bPW, 1), add(tPN, bPN, 1);
            const Prediction pr = predict(n, options.minValue, options.maxValue, models);
            const unsigned stored = access::dagStoredBit(unsigned(x), unsigned(y), unsigned(z), place.mirror);
            const uint64_t entry = e + uint64_t(std::popcount(mask & ((uint64_t(1) << stored) - 1)));
            const int64_t v = step(*pr.ctx, pr.signs, pr.value, entry);
            SampleRecord r;
            learn(pr, v, r);
            self.value[p] = int32_t(v);
            self.rec[p] = CompactRecord::of(r);
            self.done |= uint64_t(1) << p;
            last = v;
            lastRec = r;
        }
        e += uint64_t(std::popcount(mask));
    }
    if (e != entries) throw Error("the layout holds " + std::to_string(e) + " entries, the channel " + std::to_string(entries));
}

} // namespace

uint64_t layoutEntryCount(std::span<const uint64_t> layout) {
    uint64_t n = 0;
    for (const uint64_t mask : layout) n += mask ? uint64_t(std::popcount(mask)) : 1;
    return n;
}


std::vector<uint8_t> encodeBrickValues(std::span<const int32_t> entries, std::span<const uint64_t> layout, const IntCoderOptions& options,
                                       std::vector<int32_t>* reconstructed) {
    return encodeSamples(entries, options, reconstructed, [&](Models& models, auto&& step) { walk(layout, entries.size(), options, models, step); });
}

void decodeBrickValues(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, const IntCoderOptions& options, std::span<int32_t> out,
                       const std::string& what) {
    decodeSamples(bytes, options, out, what, [&](Models& models, auto&& step) { walk(layout, out.size(), options, models, step); });
}

std::vector<uint8_t> encodePlacedBrickValues(std::span<const int32_t> entries, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                                             const IntCoderOptions& options, std::vector<int32_t>* reconstructed) {
    return encodeSamples(entries, options, reconstructed, [&](Models& models, auto&& step) { walkPlaced(layout, places, entries.size(), options, models, step); });
}

void decodePlacedBrickValues(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                             const IntCoderOptions& options, std::span<int32_t> out, const std::string& what) {
    decodeSamples(bytes, options, out, what, [&](Models& models, auto&& step) { walkPlaced(layout, places, out.size(), options, models, step); });
}

} // namespace vdbdag::coding
