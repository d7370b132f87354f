// See FloatValueCoder.h.
#include "src/coding/FloatValueCoder.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cfloat>
#include <cmath>
#include <limits>

#include "src/coding/PlacedWalk.h"
#include "src/coding/RangeCoder.h"
#include "src/coding/ThreadLease.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using detail::PlacedNeighbours;
using detail::walkPlacedBricks;

constexpr int kPredictors = 8;
constexpr int kErrorContexts = 62;                 // 0..61: by the expected residual's length
constexpr int kNoNeighbourContext = 62;            // a voxel with none of W, N, P, NW
constexpr int kTileContext = 63;                   // a tile, predicted by the tile before
constexpr int kContextsPerGroup = 64;
constexpr int kContexts = 4 * kContextsPerGroup;  // group 0: a first component; 1-3: later ones, by the surprise before
constexpr int kMaxLength = 32;                     // |residual| < 2^32
constexpr uint8_t kModelGeneration = 0;

struct FloatModels {
    std::array<std::array<BitModel, 64>, kContexts> length;  // the bit length's tree, nodes 1..63
    std::array<BitModel, kContexts> sign;
    std::array<std::array<std::array<BitModel, 4>, kMaxLength + 1>, kContexts> high;  // two bits below the leading one, as a prefix tree
    // Back to a new walk's state, in place (ThreadLease.h).
    void restart() {
        for (auto& tree : length) tree.fill(BitModel{});
        sign.fill(BitModel{});
        for (auto& byLength : high)
            for (auto& tree : byLength) tree.fill(BitModel{});
    }
};

// Float bits as an unsigned integer in the floats' order, and back.
constexpr uint32_t ordered(uint32_t u) { return (u & 0x80000000u) ? ~u : (u | 0x80000000u); }
constexpr uint32_t unordered(uint32_t o) { return (o & 0x80000000u) ? (o & 0x7FFFFFFFu) : ~o; }

// The bits of the value whose ordered form, shifted right by `shift`, is q
// (the low bits those of a value with `shift` zero low bits).
uint32_t fromShifted(uint64_t q, unsigned shift) {
    const uint32_t o = uint32_t(q << shift);
    const uint32_t fill = (o & 0x80000000u) ? 0u : uint32_t((uint64_t(1) << shift) - 1);
    return unordered(o | fill);
}

// A neighbour's value as the predictors read it: false for NaN and
// infinities, 0 for a subnormal (so denormals-are-zero modes agree).
bool predictable(uint32_t u, double& v) {
    const uint32_t exponent = (u >> 23) & 0xFFu;
    if (exponent == 0xFFu) return false;
    v = exponent == 0 ? 0.0 : double(std::bit_cast<float>(u));
    return true;
}

// The one rounding from double to float: 0 below FLT_MIN in magnitude (and
// for NaN), +-FLT_MAX above it, else round to nearest. Flush-to-zero modes
// never see a subnormal result.
float toFloat(double d) {
    const double a = std::fabs(d);
    if (!(a >= double(FLT_MIN))) return 0.0f;
    if (a > double(FLT_MAX)) return d < 0 ? -FLT_MAX : FLT_MAX;
    return float(d);
}

// An error (>= 0) kept in 16 bits: the upper half of toFloat(e)'s bits
// (sign, exponent, 7 mantissa bits; truncated), and back: normal or 0.
// Written without branches (it runs eight times a voxel).
uint16_t errorCode(double e) {
    e = !(e >= double(FLT_MIN)) ? 0.0 : e;
    e = e > double(FLT_MAX) ? double(FLT_MAX) : e;
    return uint16_t(std::bit_cast<uint32_t>(float(e)) >> 16);
}
float errorOf(uint16_t code) { return std::bit_cast<float>(uint32_t(code) << 16); }
constexpr uint16_t kLargestError = 0x7F7F;  // FLT_MAX's upper half

uint32_t shiftedOf(float f, unsigned shift) { return ordered(std::bit_cast<uint32_t>(f)) >> shift; }

// What a coded voxel leaves for its neighbours, per component: each
// predictor's error (errorCode), the component's bits, and how its residual
// compared with what its context expected (for the next component's context).
template <int C>
struct VoxelRecord {
    std::array<std::array<uint16_t, kPredictors>, C> err;
    std::array<uint32_t, C> bits;
    std::array<uint8_t, C> surprise;  // 0: residual shorter than expected, 1: about as expected, 2: longer
};

// The walk shared by both directions, for C components per voxel (1: a
// float32 channel; 3: vec3s): step(c, context, predicted, entry) returns
// component c's bits, `predicted` its prediction's shifted ordered form.
// Component c > 0 is coded under its own contexts, split by how surprising
// component c - 1's residual was at the same voxel (the cross-component
// context; a single component uses contexts 0..63 only).
template <int C, typename Step>
void walkFloats(std::span<const uint64_t> layout, std::span<const BrickPlace> places, uint64_t entries, const std::array<unsigned, C>& shifts,
                Step&& step) {
    using Rec = VoxelRecord<C>;
    using Nb = PlacedNeighbours<Rec>;
    std::array<uint32_t, C> lastTile{};
    walkPlacedBricks<Rec, detail::Reach::Far>(
        layout, places, entries, BrickOrder::Spatial,
        [&](uint64_t entry) {
            for (int c = 0; c < C; ++c) {
                uint32_t& last = lastTile[size_t(c)];
                last = step(c, kTileContext + (c ? kContextsPerGroup : 0), ordered(last) >> shifts[size_t(c)], entry);
            }
        },
        [&](const Nb& nb, uint64_t entry, int32_t& value, Rec& rec) {
            for (int c = 0; c < C; ++c) {
                const unsigned shift = shifts[size_t(c)];
                double v[11];
                bool has[11];
                for (int k = 0; k < 11; ++k) has[k] = nb.has(typename Nb::Which(k)) && predictable(nb.rec(typename Nb::Which(k)).bits[size_t(c)], v[k]);
                const double W = v[Nb::W], N = v[Nb::N], P = v[Nb::P];
                const bool hW = has[Nb::W], hN = has[Nb::N], hP = has[Nb::P];
                double pred[kPredictors] = {};
                bool ok[kPredictors] = {};
                if (hW && hN && hP && has[Nb::NW] && has[Nb::PW] && has[Nb::PN] && has[Nb::PNW])
                    pred[0] = W + N + P - v[Nb::NW] - v[Nb::PW] - v[Nb::PN] + v[Nb::PNW], ok[0] = true;
                if (hW && hN && has[Nb::NW]) pred[1] = W + N - v[Nb::NW], ok[1] = true;
                if (hW && hP && has[Nb::PW]) pred[2] = W + P - v[Nb::PW], ok[2] = true;
                if (hN && hP && has[Nb::PN]) pred[3] = N + P - v[Nb::PN], ok[3] = true;
                if (hW && has[Nb::WW]) pred[4] = 2.0 * W - v[Nb::WW], ok[4] = true;
                if (hN && has[Nb::NN]) pred[5] = 2.0 * N - v[Nb::NN], ok[5] = true;
                if (hP && has[Nb::PP]) pred[6] = 2.0 * P - v[Nb::PP], ok[6] = true;
                {
                    double sum = 0;
                    int n = 0;
                    if (hW) sum += W, ++n;
                    if (hN) sum += N, ++n;
                    if (hP) sum += P, ++n;
                    pred[7] = n ? sum / n : 0.0, ok[7] = true;
                }
                // Each predictor's errors at W, N, P and NW (visited: their
                // records exist, whatever their values), summed in float: the
                // terms are normal or 0, so no mode flushes anything.
                const typename Nb::Which around[4] = {Nb::W, Nb::N, Nb::P, Nb::NW};
                float error[kPredictors] = {};
                int count = 0;
                for (const auto k : around) {
                    if (!nb.has(k)) continue;
                    ++count;
                    const auto& r = nb.rec(k).err[size_t(c)];
                    for (int p = 0; p < kPredictors; ++p) error[p] += errorOf(r[size_t(p)]);
                }
                // The least error; the lowest predictor of equals (7 is always made).
                for (int p = 0; p < kPredictors; ++p) error[p] = ok[p] ? error[p] : std::numeric_limits<float>::infinity();
                float least = error[7];
                for (int p = 0; p < 7; ++p) least = std::min(least, error[p]);
                unsigned equal = 0;
                for (int p = 0; p < kPredictors; ++p) equal |= unsigned(error[p] == least) << p;
                const int best = std::countr_zero(equal);
                const float predicted = toFloat(pred[best]);
                int context = kNoNeighbourContext;
                if (count) {
                    const double magnitude = std::fabs(double(predicted));
                    const uint32_t d = shiftedOf(toFloat(magnitude + double(error[best]) / count), shift) - shiftedOf(toFloat(magnitude), shift);
                    const int length = std::bit_width(d);
                    context = std::min(kErrorContexts - 1, 2 * length + (length >= 2 ? int((d >> (length - 2)) & 1u) : 0));
                }
                const int group = c == 0 ? 0 : 1 + rec.surprise[size_t(c - 1)];
                const uint32_t qp = shiftedOf(predicted, shift);
                const uint32_t u = step(c, context + group * kContextsPerGroup, qp, entry);
                rec.bits[size_t(c)] = u;
                if constexpr (C == 1) value = int32_t(u);
                // How the residual's length compared with the context's (both in half bits).
                const uint32_t q = ordered(u) >> shift;
                const int measured = 2 * std::bit_width(q > qp ? q - qp : qp - q);
                rec.surprise[size_t(c)] = uint8_t(context >= kErrorContexts ? 1 : measured < context - 2 ? 0 : measured > context + 2 ? 2 : 1);
                auto& errors = rec.err[size_t(c)];
                double x;
                if (!predictable(u, x)) {
                    errors.fill(kLargestError);
                    continue;
                }
                // A predictor this voxel cannot make is charged twice the chosen
                // one's error.
                const uint16_t missing = errorCode(2.0 * std::fabs(pred[best] - x));
                for (int p = 0; p < kPredictors; ++p) errors[size_t(p)] = ok[p] ? errorCode(std::fabs(pred[p] - x)) : missing;
            }
        });
}

void putResidual(RangeEncoder& rc, FloatModels& m, int context, int64_t r) {
    const uint64_t magnitude = uint64_t(r < 0 ? -r : r);
    const int length = std::bit_width(magnitude);
    unsigned node = 1;
    for (int b = 5; b >= 0; --b) {
        const unsigned bit = unsigned(length >> b) & 1u;
        rc.encode(m.length[size_t(context)][node], bit);
        node = 2 * node + bit;
    }
    if (length == 0) return;
    rc.encode(m.sign[size_t(context)], r < 0);
    const int below = length - 1, modelled = std::min(below, 2);
    unsigned h = 1;
    for (int b = 0; b < modelled; ++b) {
        const unsigned bit = unsigned(magnitude >> (below - 1 - b)) & 1u;
        rc.encode(m.high[size_t(context)][size_t(length)][h], bit);
        h = 2 * h + bit;
    }
    const int rest = below - modelled;
    if (rest > 0) rc.encodeBits(uint32_t(magnitude & ((uint64_t(1) << rest) - 1)), unsigned(rest));
}

int64_t getResidual(RangeDecoder& rc, FloatModels& m, int context) {
    unsigned node = 1;
    for (int b = 0; b < 6; ++b) node = 2 * node + rc.decode(m.length[size_t(context)][node]);
    const int length = int(node - 64);
    if (length == 0) return 0;
    if (length > kMaxLength) throw Error("corrupt (a residual of " + std::to_string(length) + " bits)");
    const bool negative = rc.decode(m.sign[size_t(context)]);
    const int below = length - 1, modelled = std::min(below, 2);
    uint64_t magnitude = 1;
    unsigned h = 1;
    for (int b = 0; b < modelled; ++b) {
        const unsigned bit = rc.decode(m.high[size_t(context)][size_t(length)][h]);
        h = 2 * h + bit;
        magnitude = 2 * magnitude + bit;
    }
    const int rest = below - modelled;
    if (rest > 0) magnitude = (magnitude << rest) | rc.decodeBits(unsigned(rest));
    return negative ? -int64_t(magnitude) : int64_t(magnitude);
}

// C components per entry, interleaved in `bits`. Header: the generation,
// then each component's shift (the common zero low bits of its magnitudes:
// a half-float file's values have 13).
template <int C>
std::vector<uint8_t> encodeComponents(std::span<const uint32_t> bits, std::span<const uint64_t> layout, std::span<const BrickPlace> places) {
    std::array<unsigned, C> shifts;
    shifts.fill(31);
    for (size_t i = 0; i < bits.size(); ++i)
        if (const uint32_t m = bits[i] & 0x7FFFFFFFu) shifts[i % C] = std::min(shifts[i % C], unsigned(std::countr_zero(m)));
    std::vector<uint8_t> out{kModelGeneration};
    for (const unsigned shift : shifts) out.push_back(uint8_t(shift));
    RangeEncoder rc(out);
    const detail::ThreadLease<FloatModels> models(0);
    walkFloats<C>(layout, places, bits.size() / C, shifts, [&](int c, int context, uint32_t predicted, uint64_t entry) {
        const uint32_t u = bits[size_t(entry) * C + size_t(c)];
        putResidual(rc, *models, context, int64_t(ordered(u) >> shifts[size_t(c)]) - int64_t(predicted));
        return u;
    });
    rc.finish();
    return out;
}

template <int C>
void decodeComponents(std::span<const uint8_t> payload, std::span<const uint64_t> layout, std::span<const BrickPlace> places, std::span<uint32_t> out,
                      const std::string& what) {
    if (payload.size() < 1 + C) throw Error(what + ": corrupt (a float window shorter than its header)");
    if (payload[0] != kModelGeneration) throw Error(what + ": float model generation " + std::to_string(payload[0]) + " (this version reads 0)");
    std::array<unsigned, C> shifts;
    std::array<int64_t, C> limits;
    for (size_t c = 0; c < C; ++c) {
        shifts[c] = payload[1 + c];
        if (shifts[c] > 31) throw Error(what + ": corrupt (a float window shifted by " + std::to_string(shifts[c]) + " bits)");
        limits[c] = int64_t(1) << (32 - shifts[c]);
    }
    if (out.size() % C) throw Error(what + ": internal error: components do not fill the entries");
    const std::span<const uint8_t> stream = payload.subspan(1 + C);
    RangeDecoder rc(stream);
    const detail::ThreadLease<FloatModels> models(0);
    try {
        walkFloats<C>(layout, places, out.size() / C, shifts, [&](int c, int context, uint32_t predicted, uint64_t entry) {
            const int64_t q = int64_t(predicted) + getResidual(rc, *models, context);
            if (q < 0 || q >= limits[size_t(c)]) throw Error("corrupt (a value outside float32)");
            return out[size_t(entry) * C + size_t(c)] = fromShifted(uint64_t(q), shifts[size_t(c)]);
        });
    } catch (const Error& e) {
        throw Error(what + ": " + e.what());
    }
    if (const char* fault = rc.endFault()) throw Error(what + ": corrupt (the coded values end " + fault + ")");
}

} // namespace

std::vector<uint8_t> encodePlacedFloats(std::span<const uint32_t> bits, std::span<const uint64_t> layout, std::span<const BrickPlace> places) {
    return encodeComponents<1>(bits, layout, places);
}

void decodePlacedFloats(std::span<const uint8_t> payload, std::span<const uint64_t> layout, std::span<const BrickPlace> places, std::span<uint32_t> out,
                        const std::string& what) {
    decodeComponents<1>(payload, layout, places, out, what);
}

std::vector<uint8_t> encodePlacedFloatVectors(std::span<const uint32_t> bits, std::span<const uint64_t> layout, std::span<const BrickPlace> places) {
    if (bits.size() % 3) throw Error("internal error: vec3s entries hold 3 components");
    return encodeComponents<3>(bits, layout, places);
}

void decodePlacedFloatVectors(std::span<const uint8_t> payload, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                              std::span<uint32_t> out, const std::string& what) {
    decodeComponents<3>(payload, layout, places, out, what);
}

} // namespace vdbdag::coding
