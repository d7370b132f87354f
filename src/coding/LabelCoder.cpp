// See LabelCoder.h. One walk for both directions: `code(context models,
// candidates, value&)` codes a value (encoder) or decodes it (decoder).
#include "src/coding/LabelCoder.h"

#include <algorithm>
#include <array>
#include <bit>
#include <memory>

#include "src/coding/PlacedWalk.h"
#include "src/coding/RangeCoder.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using namespace detail;

constexpr size_t kCandidates = 4, kRecent = 32;

struct LabelModels {
    // [candidate rank][neighbours holding it, 0..8][distinct neighbour values: 1, 2, 3+]
    std::array<std::array<std::array<BitModel, 3>, 9>, kCandidates> match;
    std::array<BitModel, kRecent> recent;  // unary rank in the recent list (all ones: a new label)
    std::array<int32_t, kRecent> list{};       // the recent labels, most recent first
    size_t listSize = 0;
    void remember(int32_t v) {
        size_t i = 0;
        while (i < listSize && list[i] != v) ++i;
        if (i == listSize) i = listSize < kRecent ? listSize++ : kRecent - 1;
        for (; i > 0; --i) list[i] = list[i - 1];
        list[0] = v;
    }
};

// The neighbours' distinct values (at most kCandidates, in the order of
// LabelCoder.h), each with how many of the 8 neighbours hold it.
struct Candidates {
    std::array<int32_t, kCandidates> value{};
    std::array<unsigned, kCandidates> count{};
    size_t size = 0;
    unsigned distinct = 0;
};

template <typename Code>
void walkLabels(std::span<const uint64_t> layout, std::span<const BrickPlace> places, BrickOrder order, uint64_t entries, Code&& code) {
    using Nb = PlacedNeighbours<uint8_t>;
    walkPlacedBricks<uint8_t>(
        layout, places, entries, order, [&](uint64_t entry) { code(Candidates{}, entry); },
        [&](const Nb& nb, uint64_t entry, int32_t& value, uint8_t&) {
            Candidates c;
            std::array<int32_t, 8> seen{};
            for (const Nb::Which k : {Nb::W, Nb::N, Nb::P, Nb::NE, Nb::NW, Nb::PN, Nb::PW, Nb::PNW}) {
                if (!nb.has(k)) continue;
                const int32_t v = nb.value(k);
                unsigned i = 0;
                while (i < c.distinct && seen[i] != v) ++i;
                if (i == c.distinct) seen[c.distinct++] = v;
                size_t j = 0;
                while (j < c.size && c.value[j] != v) ++j;
                if (j == c.size && c.size < kCandidates) c.value[c.size++] = v;
                if (j < c.size) ++c.count[j];
            }
            value = code(c, entry);
        });
}

unsigned bitsFor(int32_t minValue, int32_t maxValue) {
    const uint64_t range = uint64_t(int64_t(maxValue) - minValue);
    return unsigned(64 - std::countl_zero(range));  // 0..32
}

} // namespace

std::vector<uint8_t> encodePlacedLabels(std::span<const int32_t> entries, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                                        BrickOrder order, int32_t minValue, int32_t maxValue) {
    if (minValue > maxValue) throw Error("label coder: an empty range");
    std::vector<uint8_t> out;
    RangeEncoder rc(out);
    auto m = std::make_unique<LabelModels>();
    const unsigned bits = bitsFor(minValue, maxValue);
    walkLabels(layout, places, order, entries.size(), [&](const Candidates& c, uint64_t entry) {
        const int32_t v = entries[entry];
        if (v < minValue || v > maxValue) throw Error("label coder: label " + std::to_string(v) + " lies outside its range");
        const unsigned spread = std::min(c.distinct, 3u) - (c.distinct ? 1 : 0);
        for (size_t i = 0; i < c.size; ++i) {
            const bool hit = c.value[i] == v;
            rc.encode(m->match[i][c.count[i]][spread], hit);
            if (hit) {
                m->remember(v);
                return v;
            }
        }
        size_t rank = 0;
        while (rank < m->listSize && m->list[rank] != v) ++rank;
        for (size_t i = 0; i < rank; ++i) rc.encode(m->recent[i], 1);
        if (rank < m->listSize) {
            rc.encode(m->recent[rank], 0);
        } else {  // as many ones as the list is long: a new label, then its offset
            rc.encodeDirect(uint32_t(int64_t(v) - minValue), bits);
        }
        m->remember(v);
        return v;
    });
    rc.finish();
    return out;
}

void decodePlacedLabels(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, std::span<const BrickPlace> places, BrickOrder order,
                        int32_t minValue, int32_t maxValue, std::span<int32_t> out, const std::string& what) {
    if (minValue > maxValue) throw Error(what + ": an empty label range");
    RangeDecoder rc(bytes);
    auto m = std::make_unique<LabelModels>();
    const unsigned bits = bitsFor(minValue, maxValue);
    try {
        walkLabels(layout, places, order, out.size(), [&](const Candidates& c, uint64_t entry) {
            const unsigned spread = std::min(c.distinct, 3u) - (c.distinct ? 1 : 0);
            int32_t v = 0;
            bool found = false;
            for (size_t i = 0; i < c.size && !found; ++i)
                if (rc.decode(m->match[i][c.count[i]][spread])) v = c.value[i], found = true;
            if (!found) {
                size_t rank = 0;
                while (rank < m->listSize && rc.decode(m->recent[rank])) ++rank;
                if (rank < m->listSize) {
                    v = m->list[rank];
                } else {
                    const int64_t x = int64_t(minValue) + int64_t(rc.decodeDirect(bits));
                    if (x > maxValue) throw Error("a label outside its range (corrupt)");
                    v = int32_t(x);
                }
            }
            m->remember(v);
            out[entry] = v;
            return v;
        });
    } catch (const Error& e) {
        throw Error(what + ": " + e.what());
    }
    if (const char* fault = rc.endFault()) throw Error(what + ": corrupt (the coded labels end " + fault + ")");
}

} // namespace vdbdag::coding
