// See LabelCoder.h. One walk for both directions: `code(context models,
// candidates, value&)` codes a value (encoder) or decodes it (decoder).
#include "src/coding/LabelCoder.h"

#include <algorithm>
#include <array>
#include <bit>
#include <memory>
#include <vector>

#include "src/coding/PlacedWalk.h"
#include "src/coding/RangeCoder.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using namespace detail;

constexpr size_t kCandidates = 4, kRecent = 32;
// Generation 2 (LabelCoder.h).
constexpr unsigned kShapeBits = 10;  // W N P NE NW PN PW PNW (the near eight), PE PS
constexpr size_t kLabelList = 1024;
constexpr int kRankLengths = 11;  // bit lengths of rank + 1: 1 .. 1025

// The labels met, most recent first, at most `capacity` of them (32 in
// generation 1, 1,024 in generation 2): each label coded moves to the front.
struct RecentLabels {
    explicit RecentLabels(size_t capacity) : list(capacity) {}
    std::vector<int32_t> list;
    size_t size = 0;
    void remember(int32_t v) {
        size_t i = 0;
        while (i < size && list[i] != v) ++i;
        if (i == size) i = size < list.size() ? size++ : list.size() - 1;
        for (; i > 0; --i) list[i] = list[i - 1];
        list[0] = v;
    }
};

struct LabelModels {
    // [candidate rank][neighbours holding it, 0..8][distinct neighbour values: 1, 2, 3+]
    std::array<std::array<std::array<BitModel, 3>, 9>, kCandidates> match;
    std::array<BitModel, kRecent> recent;  // unary rank in the recent list (all ones: a new label)
    RecentLabels labels{kRecent};
};

struct ShapeModels {
    ShapeModels() {
        for (BitModel& m : match) m.warmUp();
        for (BitModel& m : tileMatch) m.warmUp();
        for (BitModel& m : rankLength) m.warmUp();
        for (auto& row : rankBits)
            for (BitModel& m : row) m.warmUp();
    }
    // [candidate rank][the neighbours holding it][distinct near values: 1, 2, 3+]
    std::vector<BitModel> match = std::vector<BitModel>(kCandidates * (size_t(1) << kShapeBits) * 3);
    // Generation 3: a tile's "equals candidate i?" under the candidate's
    // rank, which of the tiles W, N, P of its size hold it, and the spread.
    std::vector<BitModel> tileMatch = std::vector<BitModel>(kCandidates * 8 * 3);
    std::array<BitModel, kRankLengths> rankLength;                           // [bit length]: one more bit?
    std::array<std::array<BitModel, kRankLengths>, kRankLengths + 1> rankBits;  // [bit length][position]
    RecentLabels labels{kLabelList};
};

// The neighbours' distinct values (at most kCandidates, in the order of
// LabelCoder.h), each with how many of the near eight hold it (generation
// 1's context) and which (bit k: the k-th of W, N, P, NE, NW, PN, PW, PNW;
// with Reach::Ahead also bits 8 and 9 for PE and PS: generation 2's).
struct Candidates {
    std::array<int32_t, kCandidates> value{};
    std::array<unsigned, kCandidates> count{};
    std::array<unsigned, kCandidates> mask{};
    size_t size = 0;
    unsigned distinct = 0;  // among the near eight
};

// The distinct values of `n` neighbours (value(k), has(k)), at most
// kCandidates, each with how many hold it and which (bit k).
template <typename Has, typename Value>
Candidates candidatesOf(unsigned n, Has&& has, Value&& value) {
    Candidates c;
    std::array<int32_t, 8> seen{};
    for (unsigned k = 0; k < n; ++k) {
        if (!has(k)) continue;
        const int32_t v = value(k);
        unsigned i = 0;
        while (i < c.distinct && seen[i] != v) ++i;
        if (i == c.distinct) seen[c.distinct++] = v;
        size_t j = 0;
        while (j < c.size && c.value[j] != v) ++j;
        if (j == c.size && c.size < kCandidates) c.value[c.size++] = v;
        if (j < c.size) ++c.count[j], c.mask[j] |= 1u << k;
    }
    return c;
}

// code(candidates, entry, tile) codes or decodes an entry and returns its
// label. Generation 1 walks with Reach::Near, generation 2 with
// Reach::Ahead, generation 3 also with tiles as neighbours (kTiles: a tile
// has the candidates of the tiles W, N, P of its size; generations 1 and 2
// give a tile none).
template <Reach kReach, bool kTiles, typename Code>
void walkLabels(std::span<const uint64_t> layout, std::span<const BrickPlace> places, BrickOrder order, uint64_t entries, Code&& code) {
    using Nb = PlacedNeighbours<uint8_t>;
    const auto voxel = [&](const Nb& nb, uint64_t entry, int32_t& value, uint8_t&) {
        static constexpr Nb::Which kNear[] = {Nb::W, Nb::N, Nb::P, Nb::NE, Nb::NW, Nb::PN, Nb::PW, Nb::PNW};
        Candidates c = candidatesOf(8, [&](unsigned k) { return nb.has(kNear[k]); }, [&](unsigned k) { return nb.value(kNear[k]); });
        if constexpr (kReach == Reach::Ahead) {
            static constexpr Nb::Which kAhead[] = {Nb::PE, Nb::PS};
            for (unsigned k = 0; k < 2; ++k) {
                if (!nb.has(kAhead[k])) continue;
                const int32_t v = nb.value(kAhead[k]);
                for (size_t j = 0; j < c.size; ++j)
                    if (c.value[j] == v) c.mask[j] |= 1u << (8 + k);
            }
        }
        value = code(c, entry, false);
    };
    if constexpr (kTiles) {
        walkPlacedBricks<uint8_t, kReach, true>(
            layout, places, entries, order,
            [&](uint64_t entry, const TileNeighbours& tn) {
                return code(candidatesOf(TileNeighbours::kCount, [&](unsigned k) { return tn.has[k]; }, [&](unsigned k) { return tn.value[k]; }), entry,
                            true);
            },
            voxel);
    } else {
        walkPlacedBricks<uint8_t, kReach>(layout, places, entries, order, [&](uint64_t entry) { code(Candidates{}, entry, true); }, voxel);
    }
}

// One direction of generation 2's coding: bit(model, b) codes b (the
// writer) or returns the decoded bit (the reader, which ignores b).
struct LabelWriter {
    static constexpr bool kEncoding = true;
    RangeEncoder& rc;
    unsigned bit(BitModel& m, unsigned b) { return rc.encode(m, b), b; }
    uint32_t direct(uint32_t v, unsigned bits) { return rc.encodeDirect(v, bits), v; }
};
struct LabelReader {
    static constexpr bool kEncoding = false;
    RangeDecoder& rc;
    unsigned bit(BitModel& m, unsigned) { return rc.decode(m); }
    uint32_t direct(uint32_t, unsigned bits) { return rc.decodeDirect(bits); }
};

// Codes label `v` (the writer's; the reader's is ignored) given its
// candidates; returns the label coded.
template <typename IO>
int32_t codeShaped(IO& io, ShapeModels& m, const Candidates& c, bool tile, int32_t v, int32_t minValue, int32_t maxValue, unsigned bits) {
    const unsigned spread = std::min(c.distinct, 3u) - (c.distinct ? 1 : 0);
    for (size_t i = 0; i < c.size; ++i)
        if (io.bit(tile ? m.tileMatch[((i << 3) | c.mask[i]) * 3 + spread] : m.match[((i << kShapeBits) | c.mask[i]) * 3 + spread],
                   unsigned(IO::kEncoding && c.value[i] == v))) {
            m.labels.remember(c.value[i]);
            return c.value[i];
        }
    // rank + 1 in Elias-gamma form; rank = the list's length: a new label.
    uint64_t r = 0;
    if constexpr (IO::kEncoding) {
        size_t rank = 0;
        while (rank < m.labels.size && m.labels.list[rank] != v) ++rank;
        r = rank + 1;
    }
    const int length = 64 - std::countl_zero(r);
    int L = 1;
    while (L < kRankLengths && io.bit(m.rankLength[size_t(L)], unsigned(L < length))) ++L;
    uint64_t got = 1;
    for (int j = L - 2; j >= 0; --j) got = got << 1 | io.bit(m.rankBits[size_t(L)][size_t(j)], unsigned(r >> j) & 1u);
    const uint64_t rank = got - 1;
    int32_t label;
    if (rank < m.labels.size) {
        label = m.labels.list[size_t(rank)];
    } else if (rank == m.labels.size) {
        const int64_t x = int64_t(minValue) + int64_t(io.direct(uint32_t(int64_t(v) - minValue), bits));
        if (x > maxValue) throw Error("a label outside its range (corrupt)");
        label = int32_t(x);
    } else {
        throw Error("a label's rank beyond the labels met (corrupt)");
    }
    m.labels.remember(label);
    return label;
}

unsigned bitsFor(int32_t minValue, int32_t maxValue) {
    const uint64_t range = uint64_t(int64_t(maxValue) - minValue);
    return unsigned(64 - std::countl_zero(range));  // 0..32
}

} // namespace

std::vector<uint8_t> encodePlacedLabels(std::span<const int32_t> entries, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                                        BrickOrder order, int32_t minValue, int32_t maxValue, int generation) {
    if (minValue > maxValue) throw Error("label coder: an empty range");
    if (generation < 1 || generation > 3) throw Error("internal error: label model generation " + std::to_string(generation));
    std::vector<uint8_t> out;
    RangeEncoder rc(out);
    const unsigned bits = bitsFor(minValue, maxValue);
    if (generation >= 2) {
        auto m = std::make_unique<ShapeModels>();
        LabelWriter io{rc};
        const auto code = [&](const Candidates& c, uint64_t entry, bool tile) {
            const int32_t v = entries[entry];
            if (v < minValue || v > maxValue) throw Error("label coder: label " + std::to_string(v) + " lies outside its range");
            return codeShaped(io, *m, c, tile, v, minValue, maxValue, bits);
        };
        if (generation == 3) walkLabels<Reach::Ahead, true>(layout, places, order, entries.size(), code);
        else walkLabels<Reach::Ahead, false>(layout, places, order, entries.size(), code);
        rc.finish();
        return out;
    }
    auto m = std::make_unique<LabelModels>();
    walkLabels<Reach::Near, false>(layout, places, order, entries.size(), [&](const Candidates& c, uint64_t entry, bool) {
        const int32_t v = entries[entry];
        if (v < minValue || v > maxValue) throw Error("label coder: label " + std::to_string(v) + " lies outside its range");
        const unsigned spread = std::min(c.distinct, 3u) - (c.distinct ? 1 : 0);
        for (size_t i = 0; i < c.size; ++i) {
            const bool hit = c.value[i] == v;
            rc.encode(m->match[i][c.count[i]][spread], hit);
            if (hit) {
                m->labels.remember(v);
                return v;
            }
        }
        size_t rank = 0;
        while (rank < m->labels.size && m->labels.list[rank] != v) ++rank;
        for (size_t i = 0; i < rank; ++i) rc.encode(m->recent[i], 1);
        if (rank < m->labels.size) {
            rc.encode(m->recent[rank], 0);
        } else {  // as many ones as the list is long: a new label, then its offset
            rc.encodeDirect(uint32_t(int64_t(v) - minValue), bits);
        }
        m->labels.remember(v);
        return v;
    });
    rc.finish();
    return out;
}

void decodePlacedLabels(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, std::span<const BrickPlace> places, BrickOrder order,
                        int32_t minValue, int32_t maxValue, std::span<int32_t> out, const std::string& what, int generation) {
    if (minValue > maxValue) throw Error(what + ": an empty label range");
    if (generation < 1 || generation > 3) throw Error(what + ": internal error: label model generation " + std::to_string(generation));
    RangeDecoder rc(bytes);
    const unsigned bits = bitsFor(minValue, maxValue);
    try {
        if (generation >= 2) {
            auto m = std::make_unique<ShapeModels>();
            LabelReader io{rc};
            const auto code = [&](const Candidates& c, uint64_t entry, bool tile) {
                return out[entry] = codeShaped(io, *m, c, tile, 0, minValue, maxValue, bits);
            };
            if (generation == 3) walkLabels<Reach::Ahead, true>(layout, places, order, out.size(), code);
            else walkLabels<Reach::Ahead, false>(layout, places, order, out.size(), code);
        } else {
            auto m = std::make_unique<LabelModels>();
            walkLabels<Reach::Near, false>(layout, places, order, out.size(), [&](const Candidates& c, uint64_t entry, bool) {
                const unsigned spread = std::min(c.distinct, 3u) - (c.distinct ? 1 : 0);
                int32_t v = 0;
                bool found = false;
                for (size_t i = 0; i < c.size && !found; ++i)
                    if (rc.decode(m->match[i][c.count[i]][spread])) v = c.value[i], found = true;
                if (!found) {
                    size_t rank = 0;
                    while (rank < m->labels.size && rc.decode(m->recent[rank])) ++rank;
                    if (rank < m->labels.size) {
                        v = m->labels.list[rank];
                    } else {
                        const int64_t x = int64_t(minValue) + int64_t(rc.decodeDirect(bits));
                        if (x > maxValue) throw Error("a label outside its range (corrupt)");
                        v = int32_t(x);
                    }
                }
                m->labels.remember(v);
                out[entry] = v;
                return v;
            });
        }
    } catch (const Error& e) {
        throw Error(what + ": " + e.what());
    }
    if (const char* fault = rc.endFault()) throw Error(what + ": corrupt (the coded labels end " + fault + ")");
}

} // namespace vdbdag::coding
