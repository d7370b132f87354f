// See BrickValueCoder.h. One template walks the entries for both
// directions, as IntVolumeCoder.cpp does.
#include "src/coding/BrickValueCoder.h"

#include <array>
#include <bit>
#include <memory>
#include <type_traits>

#include "src/coding/CodingLoop.h"
#include "src/coding/PlacedWalk.h"
#include "src/coding/SamplePredictor.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using namespace detail;

// `step(prediction, entry)` returns the reconstructed entry. Each brick sees
// only itself (coding 2, generation 0): the far neighbours are W's value.
template <typename Step>
void walk(std::span<const uint64_t> layout, uint64_t entries, const IntCoderOptions& options, Models& models, Step&& step) {
    int64_t value[64];
    SampleRecord rec[64];
    int64_t last = 0;         // the previous entry in attribute order
    SampleRecord lastRec{};   // and its record
    uint64_t e = 0;
    const auto code = [&](Neighbourhood& n) {
        const Prediction pr = predict(n, options.minValue, options.maxValue, models);
        const int64_t v = step(pr, e++);
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
            n.far.fill(last);
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
            n.far.fill(n.W);
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

// What a coded voxel keeps for its neighbours, compactly (the walk holds
// every coded brick a later brick may still read, PlacedWalk.h): errors and
// residual saturated at 2^16 - 1.
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
    // Written field by field where it lives: a temporary copied over it
    // stalled on its own partial stores (store-to-load forwarding).
    void set(const SampleRecord& r) {
        for (size_t k = 0; k < size_t(kPredictors); ++k) err[k] = uint16_t(std::min<uint32_t>(r.err[k], 65535));
        residual = uint16_t(std::min<uint32_t>(r.residual, 65535)), sign = r.sign;
    }
};

// A voxel's record in a walk with a series' reference (IntCoderOptions::
// reference): also the reference's entry at the voxel, which its later
// neighbours read as TW, TN and TP. A tile beside a brick stands in with
// its record Rec{}: a reference of 0 there.
struct ReferencedRecord : CompactRecord {
    int32_t t = 0;
};

// Generation 2 (kReach Wide) also finds the far neighbours, generation 3
// (Widest) five more, with the raster walk's substitutes (IntVolumeCoder.cpp)
// where a neighbour's brick is not visited yet. With a reference (kRef,
// generations 3 and 4), the reference's entry at the voxel (T) and at W, N
// and P (TW, TN, TP; T where that neighbour is not visited) take the taps
// of NNN, WWWW, NWWW and NEEE, as the raster walk's reference does.
template <Reach kReach, bool kTiles, bool kRef = false, typename Step>
void walkPlaced(std::span<const uint64_t> layout, std::span<const BrickPlace> places, uint64_t entries, BrickOrder order, const IntCoderOptions& options,
                Models& models, Step&& step) {
    static_assert(!kRef || kReach == Reach::Widest, "a reference takes generation 3's far taps");
    using Rec = std::conditional_t<kRef, ReferencedRecord, CompactRecord>;
    if (kRef && options.reference.size() != entries)
        throw Error("value coder: a reference of " + std::to_string(options.reference.size()) + " entries for " + std::to_string(entries));
    int64_t last = 0;  // the previous entry visited, and its record
    SampleRecord lastRec{};
    using Nb = PlacedNeighbours<Rec>;
    walkPlacedBricks<Rec, kReach, kTiles>(
        layout, places, entries, order,
        [&](uint64_t entry, auto&&...) {  // a tile: one entry, predicted by the entry before (kTiles: its value a neighbour's)
            Neighbourhood n;
            n.W = n.N = n.NW = n.NE = n.P = n.PW = n.PN = n.PNW = last;
            n.far.fill(last);
            n.rW = &lastRec;
            const Prediction pr = predict(n, options.minValue, options.maxValue, models);
            last = step(pr, entry);
            learn(pr, last, lastRec);
            return int32_t(last);
        },
        [&](const Nb& nb, uint64_t entry, int32_t& value, Rec& rec) {
            const auto v = [&](typename Nb::Which k) { return int64_t(nb.value(k)); };
            const bool hW = nb.has(Nb::W), hN = nb.has(Nb::N), hP = nb.has(Nb::P);
            Neighbourhood n;
            n.W = hW ? v(Nb::W) : hN ? v(Nb::N) : hP ? v(Nb::P) : last;
            n.N = hN ? v(Nb::N) : n.W;
            n.NW = nb.has(Nb::NW) ? v(Nb::NW) : n.N;
            n.NE = nb.has(Nb::NE) ? v(Nb::NE) : n.N;
            if (hP) {
                n.P = v(Nb::P);
                n.PW = nb.has(Nb::PW) ? v(Nb::PW) : n.P;
                n.PN = nb.has(Nb::PN) ? v(Nb::PN) : n.PW;
                n.PNW = nb.has(Nb::PNW) ? v(Nb::PNW) : n.PN;
            } else {
                n.P = med(n.W, n.N, n.NW), n.PW = n.W, n.PN = n.N, n.PNW = n.NW;
            }
            if constexpr (kReach >= Reach::Wide) {
                const auto o = [&](typename Nb::Which k, int64_t substitute) { return nb.has(k) ? v(k) : substitute; };
                n.far[kWW] = o(Nb::WW, n.W), n.far[kNN] = o(Nb::NN, n.N), n.far[kPP] = o(Nb::PP, n.P);
                n.far[kPE] = o(Nb::PE, n.P), n.far[kPS] = o(Nb::PS, n.P), n.far[kPNE] = o(Nb::PNE, n.PN), n.far[kPSW] = o(Nb::PSW, n.PW);
                n.far[kPSE] = o(Nb::PSE, n.far[kPS]), n.far[kNWW] = o(Nb::NWW, n.NW), n.far[kNNE] = o(Nb::NNE, n.far[kNN]);
                n.far[kNNW] = o(Nb::NNW, n.far[kNN]), n.far[kNEE] = o(Nb::NEE, n.NE);
                if constexpr (kReach == Reach::Widest) {
                    n.far[kWWW] = o(Nb::WWW, n.far[kWW]), n.far[kWWWW] = o(Nb::WWWW, n.far[kWWW]), n.far[kNWWW] = o(Nb::NWWW, n.far[kNWW]);
                    n.far[kNEEE] = o(Nb::NEEE, n.far[kNEE]), n.far[kNNN] = o(Nb::NNN, n.far[kNN]);
                    for (const typename Nb::Which k : {Nb::WW, Nb::NN, Nb::NEE})
                        if (nb.has(k)) n.residualsFar += nb.rec(k).residual;
                    if constexpr (kRef) {
                        const int32_t t = options.reference[size_t(entry)];
                        rec.t = t;
                        n.far[kNNN] = t;
                        n.far[kWWWW] = hW ? nb.rec(Nb::W).t : t;
                        n.far[kNWWW] = hN ? nb.rec(Nb::N).t : t;
                        n.far[kNEEE] = hP ? nb.rec(Nb::P).t : t;
                    }
                }
            } else {
                n.far.fill(n.W);
            }
            SampleRecord rW, rN, rP;
            if (hW) rW = nb.rec(Nb::W).expand();
            if (hN) rN = nb.rec(Nb::N).expand();
            if (hP) rP = nb.rec(Nb::P).expand();
            n.rW = hW ? &rW : (!hN && !hP) ? &lastRec : nullptr;
            n.rN = hN ? &rN : nullptr;
            n.rP = hP ? &rP : nullptr;
            const auto add = [&](typename Nb::Which k, unsigned times) {
                if (!nb.has(k)) return;
                const CompactRecord& r = nb.rec(k);  // (a ReferencedRecord's base)
                if constexpr (kReach < Reach::Wide)  // generations 2 and 3 have no blend to weigh
                    for (size_t j = 0; j < size_t(kPredictors); ++j) n.errorsAbove[j] += times * uint64_t(r.err[j]);
                n.residualsAbove += times * uint64_t(r.residual);
            };
            add(Nb::N, 2), add(Nb::P, 2), add(Nb::NE, 1), add(Nb::NW, 1), add(Nb::PW, 1), add(Nb::PN, 1);
            const Prediction pr = predict(n, options.minValue, options.maxValue, models);
            const int64_t decoded = step(pr, entry);
            SampleRecord r;
            learn(pr, decoded, r);
            value = int32_t(decoded);
            rec.set(r);
            last = decoded;
            lastRec = r;
        });
}

template <typename Step>
void walkPlacedAny(std::span<const uint64_t> layout, std::span<const BrickPlace> places, uint64_t entries, BrickOrder order, const IntCoderOptions& options,
                   Models& models, Step&& step) {
    if (options.tileNeighbours && options.model != 4) throw Error("internal error: tiles as neighbours are model generation 4's");
    if (!options.reference.empty() && options.model < 3) throw Error("internal error: a series' reference needs model generation 3 or later");
    if (!options.reference.empty()) {
        if (options.tileNeighbours) walkPlaced<Reach::Widest, true, true>(layout, places, entries, order, options, models, step);
        else walkPlaced<Reach::Widest, false, true>(layout, places, entries, order, options, models, step);
    } else if (options.tileNeighbours) walkPlaced<Reach::Widest, true>(layout, places, entries, order, options, models, step);
    else if (options.model >= 3) walkPlaced<Reach::Widest, false>(layout, places, entries, order, options, models, step);
    else if (options.model == 2) walkPlaced<Reach::Wide, false>(layout, places, entries, order, options, models, step);
    else walkPlaced<Reach::Near, false>(layout, places, entries, order, options, models, step);
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
                                             BrickOrder order, const IntCoderOptions& options, std::vector<int32_t>* reconstructed) {
    return encodeSamples(entries, options, reconstructed,
                         [&](Models& models, auto&& step) { walkPlacedAny(layout, places, entries.size(), order, options, models, step); });
}

void decodePlacedBrickValues(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, std::span<const BrickPlace> places, BrickOrder order,
                             const IntCoderOptions& options, std::span<int32_t> out, const std::string& what) {
    decodeSamples(bytes, options, out, what, [&](Models& models, auto&& step) { walkPlacedAny(layout, places, out.size(), order, options, models, step); });
}

} // namespace vdbdag::coding
