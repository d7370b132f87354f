// The per-sample model of the integer value coders (docs/CODING.md): six
// predictions from a causal 3-D neighbourhood blended by their local errors
// (generations 0 and 1) or a least-squares fit over 19 or 24 neighbours
// (generations 2 and 3, LeastSquaresPredictor.h), an activity context, bias
// correction (per activity context, generation 0, or per activity context
// and texture, generations 1 to 3), and the residual's binary coding.
// Generations 2 and 3 also code "the sample is the range's minimum" first where a
// neighbour holds it (a scan's background at a tissue's edge).
// IntVolumeCoder walks a raster box with it, BrickValueCoder the 4^3 bricks
// of a DAG's attribute order; both hand it the same neighbourhood
//      this slice:  NW N NE        previous slice:  PNW PN
//                   W  *                            PW  P
// (with substitutes where a neighbour is missing) and the records the
// neighbours left, so the two cannot drift apart.
#pragma once
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "src/coding/IntVolumeCoder.h"
#include "src/coding/LeastSquaresPredictor.h"
#include "src/coding/RangeCoder.h"

namespace vdbdag::coding::detail {

inline constexpr int kPredictors = 6;
inline constexpr int kContexts = 44;    // residual-activity buckets: half bit lengths
inline constexpr int kMaxLength = 40;   // bit length of a residual magnitude (|e| < 2^34 fits)
inline constexpr int kBiasWindow = 64;  // bias statistics are halved at this count
inline constexpr int kTextures = 64;    // 6 neighbours above or not above the blend
inline constexpr int kBands = 16;       // generation 4: intensity bands of the prediction (intensityBand)

// What a coded sample leaves for its neighbours: each predictor's error and
// the final residual's magnitude and sign.
struct SampleRecord {
    std::array<uint32_t, kPredictors> err{};
    uint32_t residual = 0;
    int8_t sign = 0;  // -1, 0, 1
};

// A bias correction's statistics: the summed error of the blend and how
// many samples it sums (both halved every kBiasWindow samples).
struct BiasCell {
    int64_t sum = 0;
    int32_t count = 0;
};

// The models of one activity context.
struct ContextModels {
    std::array<BitModel, 27> zero, sign;                        // by the signs of W's, N's and P's residuals
    std::array<BitModel, kMaxLength + 1> length;                // unary bit length
    std::array<std::array<BitModel, 4>, kMaxLength + 1> high;   // the two bits below the leading one, as a prefix tree
    BiasCell bias;                                              // generation 0's bias correction
};

inline constexpr int kLatestModel = kLatestIntModel;

struct Models {
    explicit Models(int generation)
        : generation(generation), textureBias(generation >= 1), leastSquares(generation >= 2), farActivity(generation >= 3),
          intensityBands(generation >= 4), bands(intensityBands ? kBands : 1), ctx(size_t(kContexts) * bands),
          bias(size_t(kContexts) * kTextures * bands) {
        restart();
    }
    // Back to the state a walk starts from, in place (ModelsLease, CodingLoop.h).
    void restart() {
        std::fill(ctx.begin(), ctx.end(), ContextModels{});
        for (auto& row : low) row.fill(BitModel{});
        std::fill(bias.begin(), bias.end(), BiasCell{});
        for (LeastSquaresFit& f : fit) {
            f = LeastSquaresFit{};
            f.shape = generation >= 3 ? kLsGeneration3 : kLsGeneration2;
        }
        floor.fill(BitModel{});
        if (intensityBands) {  // 16 times the residual models: each learns its first bits fast (BitModel::warmUp)
            for (ContextModels& c : ctx) {
                for (BitModel& m : c.zero) m.warmUp();
                for (BitModel& m : c.sign) m.warmUp();
                for (BitModel& m : c.length) m.warmUp();
                for (auto& tree : c.high)
                    for (BitModel& m : tree) m.warmUp();
            }
            for (auto& row : low)
                for (BitModel& m : row) m.warmUp();
            for (BitModel& m : floor) m.warmUp();
        }
    }
    int generation;
    bool textureBias;   // generations 1-3: the bias corrections below, not the contexts' own
    bool leastSquares;  // generations 2, 3: the fits below predict, and the floor flags
    // Generation 3: the activity also counts the residuals at WW, NN and NEE
    // (Neighbourhood::residualsFar; 0.1-0.3 % smaller on the shared scans).
    bool farActivity;
    // Generation 4: the residual's models and the bias corrections also by
    // the intensity band of the prediction (intensityBand). A scan's noise
    // depends on its intensity, and on a log scale most: an MR's background
    // and CSF (Rician noise near 0) are quieter than its tissue, a CT's air
    // than its bone; the activity around a sample cannot tell a dark quiet
    // region from a bright one. Every model of generation 4 warms up
    // (BitModel::warmUp): 16 times the models learn 16 times as often from
    // 1/2. With both, 0.1-2.9 % smaller than generation 3 on the shared
    // scans (cthead 2.9 %, ch2 2.4 %, adi_brain 0.8-1.0 %; the tooth, whose
    // noise does not follow its intensity, 0.1 %), 1-4 % slower
    // (docs/CODING.md "Generation 4"). Linear bands (8 or 16 of the range)
    // gained 0.1 %.
    bool intensityBands;
    // The bands the models below are kept for: kBands in generation 4, else
    // 1 (the arrays are sized by it: 115 KB of models before generation 4,
    // 1.9 MB in it, built for every window).
    size_t bands;
    std::vector<ContextModels> ctx;  // [context][band]
    std::array<std::array<BitModel, kMaxLength + 1>, kMaxLength + 1> low;  // [length][bit]: the remaining bits
    // Generation 1's bias corrections, per activity context and texture:
    // which of W, N, P, NW, NE, PN lie above the blend (CALIC's texture
    // context in 3-D). A blend under-shoots an edge on the side its
    // neighbours lie, and by an amount the activity scales; one correction
    // per context cannot see which side. On the shared scans 1-2.4 % smaller
    // (tooth the most: 637,721 -> 622,454 bytes in raster order).
    std::vector<BiasCell> bias;  // [context][texture][band]
    // Generation 2's and 3's fits, one per kContextsPerFit activity contexts: four
    // (two bit lengths of the activity) beat one per context on every scan
    // (cthead 1.3 %, tooth 0.1 %: more samples per fit), and beat eight
    // (tooth 0.5 %) and one for all (cthead 1.5 %).
    static constexpr int kContextsPerFit = 4;
    std::array<LeastSquaresFit, (kContexts + kContextsPerFit - 1) / kContextsPerFit> fit;
    // Generation 2's (and 3's) "the sample is the minimum" flag, coded before the
    // residual where 1-7 of W, N, NW, NE, P, PW, PN hold the minimum and the
    // prediction does not: by how many (the edge of a skull-stripped MR's
    // zero background: FLAIR 2.2 % smaller) and the activity (8 buckets).
    std::array<BitModel, 64> floor;
};

// Generation 4's intensity band of a prediction v above the range's minimum
// (v >= 0): its bit length L doubled plus the bit below the leading one,
// capped at 15 (so 0, 1, 2, 3, 4-5, 6-7, 8-11, ... , 128 and up).
// `halves`: with the bit below the leading one (the residual's models), or
// the bit length alone, capped at 15 (the bias corrections).
inline int intensityBand(int64_t v, bool halves) {
    const int length = 64 - std::countl_zero(uint64_t(v));
    if (!halves) return std::min(kBands - 1, length);
    return std::min(kBands - 1, 2 * length + (length >= 2 ? int(uint64_t(v) >> (length - 2)) & 1 : 0));
}

inline uint32_t saturate(int64_t v) { return v > int64_t(UINT32_MAX) ? UINT32_MAX : uint32_t(v); }

// a / b rounded half away from zero (b > 0); in 32 bits where both fit (the
// same quotient: a 64-bit division was a tenth of the coder's time).
inline int64_t divRound(int64_t a, int64_t b) {
    if (a > -(int64_t(1) << 30) && a < (int64_t(1) << 30) && b < (int64_t(1) << 30)) {
        const int32_t a32 = int32_t(a), b32 = int32_t(b);
        return a32 >= 0 ? (a32 + b32 / 2) / b32 : -((-a32 + b32 / 2) / b32);
    }
    return a >= 0 ? (a + b / 2) / b : -((-a + b / 2) / b);
}

inline int64_t med(int64_t w, int64_t n, int64_t nw) {
    if (nw >= std::max(w, n)) return std::min(w, n);
    if (nw <= std::min(w, n)) return std::max(w, n);
    return w + n - nw;
}

// A predictor's weight from its summed local errors E: 2^26 / (1 + E)^2 + 1
// (E capped at 2^13), from a table: the blend's only divisions otherwise.
// 2^26 keeps the weighted sum of six int32 predictions inside int64.
inline constexpr uint32_t kWeightCap = 1u << 13;
inline constexpr std::array<uint32_t, kWeightCap + 1> kWeights = [] {
    std::array<uint32_t, kWeightCap + 1> t{};
    for (uint64_t e = 0; e <= kWeightCap; ++e) t[e] = uint32_t((uint64_t(1) << 26) / ((1 + e) * (1 + e))) + 1;
    return t;
}();
inline int64_t weightOf(uint64_t errors) { return kWeights[errors < kWeightCap ? errors : kWeightCap]; }

// The neighbourhood of one sample: values (substitutes where missing) and
// the records of W, N and P (a default record where missing). Every walk
// sets all eight values; they have no default, so that making one per
// sample does not clear 144 bytes first (GCC's `rep stos` was a tenth of
// the placed walk's time).
struct Neighbourhood {
    int64_t W, N, NW, NE, P, PW, PN, PNW;
    std::array<int64_t, kFarNeighbours> far;  // generations 2, 3 (LeastSquaresPredictor.h): set by every walk
    const SampleRecord* rW = nullptr;
    const SampleRecord* rN = nullptr;
    const SampleRecord* rP = nullptr;
    // Summed over N, P (twice) and NE, NW, PW, PN (once): each predictor's
    // errors and the residual magnitudes. W's part is added by predict().
    std::array<uint64_t, kPredictors> errorsAbove{};
    uint64_t residualsAbove = 0;
    uint64_t residualsFar = 0;  // generation 3: the residual magnitudes at WW, NN and NEE (once each)
};

// One sample's prediction, and what it needs to learn from the sample.
// The arrays are left uninitialised (each generation sets what it reads):
// zeroing them per sample was a fifth of predict()'s time.
struct Prediction {
    std::array<int64_t, kPredictors> p;  // generations 0 and 1
    int64_t blend = 0, value = 0;  // value: the final prediction
    ContextModels* ctx = nullptr;
    ContextModels* high = nullptr;  // the models of the bits below the leading one: ctx's band 0 (a context's, in every band)
    BiasCell* bias = nullptr;
    unsigned signs = 0;
    int floor = -1;  // generation 2: the floor flag's model, or -1 when no flag is coded
    LeastSquaresFit* fit = nullptr;
    std::array<double, kLsMaxTaps> x;  // generations 2, 3: the fit's neighbours, relative to W
    int64_t W = 0;
};

inline Prediction predict(const Neighbourhood& n, int64_t minValue, int64_t maxValue, Models& models) {
    Prediction out;
    static constexpr SampleRecord none{};
    const SampleRecord& rW = n.rW ? *n.rW : none;
    const SampleRecord& rN = n.rN ? *n.rN : none;
    const SampleRecord& rP = n.rP ? *n.rP : none;
    if (!models.leastSquares) {  // generations 0 and 1: the blend of six
        const int64_t inPlane = med(n.W, n.N, n.NW);
        out.p = {inPlane, n.W + n.N + n.P - n.NW - n.PW - n.PN + n.PNW, n.P + inPlane - med(n.PW, n.PN, n.PNW), n.W + n.NE - n.N, n.N + n.P - n.PN,
                 n.W + n.P - n.PW};
        for (int64_t& q : out.p) q = std::clamp(q, minValue, maxValue);  // a prediction outside the range helps no one
        int64_t weightSum = 0, weighted = 0;  // |weighted| < 6 x (2^26 + 1) x 2^31 < 2^60
        for (size_t k = 0; k < size_t(kPredictors); ++k) {
            const int64_t w = weightOf((n.errorsAbove[k] + 2 * uint64_t(rW.err[k])) / 2);  // 2 (W + N + P) + NE + NW + PW + PN, halved
            weightSum += w;
            weighted += w * out.p[k];
        }
        out.blend = std::clamp(divRound(weighted, weightSum), std::min({n.W, n.N, n.NE, n.P}), std::max({n.W, n.N, n.NE, n.P}));
    }
    // The activity: the residuals around (W, N, P twice; generation 3 also
    // WW, NN, NEE once) and the gradients; generations 2 and 3 weigh the
    // gradients twice as much (0.3-0.5 % smaller).
    const uint64_t gradient = uint64_t(std::abs(n.W - n.NW) + std::abs(n.N - n.NW) + std::abs(n.NE - n.N) + std::abs(n.P - med(n.PW, n.PN, n.PNW)));
    const uint64_t around = n.residualsAbove + 2 * uint64_t(rW.residual) + (models.farActivity ? n.residualsFar : 0);
    const uint64_t activity = around / 2 + (models.leastSquares ? gradient : gradient / 2);
    const int length = 64 - std::countl_zero(activity);
    const int context = std::min(kContexts - 1, 2 * length + (length >= 2 ? int(activity >> (length - 2)) & 1 : 0));
    if (models.leastSquares) {
        out.fit = &models.fit[size_t(context / Models::kContextsPerFit)];
        out.W = n.W;
        const int64_t nearSeven[] = {n.N, n.NW, n.NE, n.P, n.PW, n.PN, n.PNW};
        for (size_t k = 0; k < 7; ++k) out.x[k] = double(nearSeven[k] - n.W);
        const size_t far = size_t(out.fit->shape.taps - 7);
        for (size_t k = 0; k < far; ++k) out.x[7 + k] = double(n.far[k] - n.W);
        // A prediction outside int64 (a fit whose weights a sudden jump in
        // the samples or a series' reference multiplied: found by review,
        // 2^64 from full-range int32 samples) is the range's minimum: what
        // x86-64's conversion gave it (INT64_MIN, clamped), now defined, so
        // that every machine decodes the same (ARM saturates instead).
        const double rounded = std::nearbyint(out.fit->predict(out.x, double(n.W)));
        out.blend = rounded >= -0x1p63 && rounded < 0x1p63 ? std::clamp(int64_t(rounded), minValue, maxValue) : minValue;
    }
    if (models.textureBias) {
        const int64_t b = out.blend;
        const unsigned texture = unsigned(n.W > b) | unsigned(n.N > b) << 1 | unsigned(n.P > b) << 2 | unsigned(n.NW > b) << 3 | unsigned(n.NE > b) << 4 |
                                 unsigned(n.PN > b) << 5;
        const int band = models.intensityBands ? intensityBand(b - minValue, false) : 0;
        out.bias = &models.bias[(size_t(context) * kTextures + texture) * models.bands + size_t(band)];
    } else {
        out.bias = &models.ctx[size_t(context) * models.bands].bias;
    }
    const int64_t bias = out.bias->count ? divRound(out.bias->sum, out.bias->count) : 0;
    out.value = std::clamp(out.blend + bias, minValue, maxValue);
    out.ctx = &models.ctx[size_t(context) * models.bands + size_t(models.intensityBands ? intensityBand(out.value - minValue, true) : 0)];
    out.high = &models.ctx[size_t(context) * models.bands];
    out.signs = unsigned(9 * (rP.sign + 1) + 3 * (rW.sign + 1) + (rN.sign + 1));
    if (models.leastSquares && out.value != minValue) {
        const int k = (n.W == minValue) + (n.N == minValue) + (n.NW == minValue) + (n.NE == minValue) + (n.P == minValue) + (n.PW == minValue) +
                      (n.PN == minValue);
        if (k > 0) out.floor = k + 8 * std::min(7, context / 4);
    }
    return out;
}

// What the neighbours learn from the reconstructed `value`: its record and
// the context's bias.
inline void learn(const Prediction& pr, int64_t value, SampleRecord& r) {
    if (pr.fit) {
        pr.fit->learn(pr.x, double(value - pr.W));
        r.err = {};
    } else {
        for (size_t k = 0; k < size_t(kPredictors); ++k) r.err[k] = saturate(std::abs(pr.p[k] - value));
    }
    r.residual = saturate(std::abs(value - pr.value));
    r.sign = int8_t((value > pr.value) - (value < pr.value));
    BiasCell& c = *pr.bias;
    c.sum += value - pr.blend;
    if (++c.count == kBiasWindow) {
        c.sum = divRound(c.sum, 2);
        c.count /= 2;
    }
}

// Residual coding under one context: a zero flag, a sign, the magnitude's
// bit length in unary, the two bits below the leading one (a prefix tree),
// the rest by position. `h`: the context whose models code the two bits
// below the leading one (generation 4 keeps them per activity context, not
// per band: nearly uniform bits that 16 bands only learn 16 times slower).
inline void putResidual(RangeEncoder& rc, Models& models, ContextModels& c, ContextModels& h, unsigned signs, int64_t e) {
    rc.encode(c.zero[signs], e != 0);
    if (e == 0) return;
    rc.encode(c.sign[signs], e < 0);
    const uint64_t m = uint64_t(e < 0 ? -e : e);
    const int k = 64 - std::countl_zero(m);  // 1..kMaxLength
    for (int i = 1; i < k; ++i) rc.encode(c.length[size_t(i)], 1);
    if (k < kMaxLength) rc.encode(c.length[size_t(k)], 0);
    unsigned prefix = 1;
    for (int j = k - 2; j >= 0; --j) {
        const unsigned bit = unsigned(m >> j) & 1u;
        const int depth = k - 2 - j;
        if (depth < 2) rc.encode(h.high[size_t(k)][prefix], bit);
        else rc.encode(models.low[size_t(k)][size_t(j)], bit);
        if (depth == 0) prefix = 2 + bit;  // the second bit's model knows the first
    }
}

inline int64_t getResidual(RangeDecoder& rc, Models& models, ContextModels& c, ContextModels& h, unsigned signs) {
    if (!rc.decode(c.zero[signs])) return 0;
    const bool negative = rc.decode(c.sign[signs]);
    int k = 1;
    while (k < kMaxLength && rc.decode(c.length[size_t(k)])) ++k;
    uint64_t m = 1;
    unsigned prefix = 1;
    for (int j = k - 2; j >= 0; --j) {
        const int depth = k - 2 - j;
        const unsigned bit = depth < 2 ? rc.decode(h.high[size_t(k)][prefix]) : rc.decode(models.low[size_t(k)][size_t(j)]);
        m = m << 1 | bit;
        if (depth == 0) prefix = 2 + bit;
    }
    return negative ? -int64_t(m) : int64_t(m);
}

// Lossless residuals modulo the range R = maxValue - minValue + 1, into
// [-R/2, R/2) (JPEG-LS's modulo reduction): a residual never needs more bits
// than the samples, so noise costs no more than its bit depth.
inline int64_t wrap(int64_t e, int64_t minValue, int64_t maxValue) {
    const int64_t range = maxValue - minValue + 1;
    if (e < -range / 2) e += range;
    else if (e >= range - range / 2) e -= range;
    return e;
}

// The sample the decoder rebuilds: lossless (step 1), the prediction plus
// the residual brought back into the range; near-lossless, the quantised
// residual's centre, clamped (which only brings it closer to the sample).
inline int64_t reconstruct(int64_t prediction, int64_t q, int64_t step, int64_t minValue, int64_t maxValue) {
    if (step == 1) {
        const int64_t range = maxValue - minValue + 1;
        int64_t v = prediction + q;
        if (v < minValue) v += range;
        else if (v > maxValue) v -= range;
        return std::clamp(v, minValue, maxValue);  // only a corrupt stream needs the clamp
    }
    return std::clamp(prediction + q * step, minValue, maxValue);
}

} // namespace vdbdag::coding::detail
