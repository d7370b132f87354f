// See IntVolumeCoder.h. One template walks the samples for both
// directions, so the encoder and the decoder cannot drift apart: only the
// residual step differs (code it, or read it).
#include "src/coding/IntVolumeCoder.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdlib>
#include <memory>
#include <string>

#include "src/coding/RangeCoder.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

constexpr int kPredictors = 6;
constexpr int kContexts = 44;     // residual-activity buckets: half bit lengths
constexpr int kMaxLength = 40;    // bit length of a residual magnitude (|e| < 2^34 fits)
constexpr int kBiasWindow = 64;   // bias statistics are halved at this count

// What a coded sample leaves for its neighbours: each predictor's error and
// the final residual's magnitude.
struct SampleRecord {
    std::array<uint32_t, kPredictors> err{};
    uint32_t residual = 0;
    int8_t sign = 0;  // of the final residual: -1, 0, 1
};

// The models of one activity context.
struct ContextModels {
    std::array<BitModel, 27> zero, sign;  // by the signs of W's, N's and P's residuals
    std::array<BitModel, kMaxLength + 1> length;      // unary bit length
    std::array<std::array<BitModel, 4>, kMaxLength + 1> high;  // the two bits below the leading one, as a prefix tree
    int64_t biasSum = 0;
    int32_t biasCount = 0;
};

struct Models {
    std::array<ContextModels, kContexts> ctx;
    std::array<std::array<BitModel, kMaxLength + 1>, kMaxLength + 1> low;  // [length][bit]: the remaining bits
};

uint32_t saturate(int64_t v) { return v > int64_t(UINT32_MAX) ? UINT32_MAX : uint32_t(v); }

// A predictor's weight from its summed local errors E: 2^26 / (1 + E)^2 + 1
// (E capped at 2^13), from a table: the blend's only divisions otherwise.
// 2^26 keeps the weighted sum of six int32 predictions inside int64.
constexpr uint32_t kWeightCap = 1u << 13;
int64_t weightOf(uint64_t errors) {
    static const std::vector<uint32_t> table = [] {
        std::vector<uint32_t> t(kWeightCap + 1);
        for (uint64_t e = 0; e <= kWeightCap; ++e) t[e] = uint32_t((uint64_t(1) << 26) / ((1 + e) * (1 + e))) + 1;
        return t;
    }();
    return table[errors < kWeightCap ? errors : kWeightCap];
}

int64_t divRound(int64_t a, int64_t b) { return a >= 0 ? (a + b / 2) / b : -((-a + b / 2) / b); }

int64_t med(int64_t w, int64_t n, int64_t nw) {
    if (nw >= std::max(w, n)) return std::min(w, n);
    if (nw <= std::min(w, n)) return std::max(w, n);
    return w + n - nw;
}

// Residual coding under one context (IntVolumeCoder.h).
void putResidual(RangeEncoder& rc, Models& models, ContextModels& c, unsigned signs, int64_t e) {
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
        if (depth < 2) rc.encode(c.high[size_t(k)][prefix], bit);
        else rc.encode(models.low[size_t(k)][size_t(j)], bit);
        if (depth == 0) prefix = 2 + bit;  // the second bit's model knows the first
    }
}

int64_t getResidual(RangeDecoder& rc, Models& models, ContextModels& c, unsigned signs) {
    if (!rc.decode(c.zero[signs])) return 0;
    const bool negative = rc.decode(c.sign[signs]);
    int k = 1;
    while (k < kMaxLength && rc.decode(c.length[size_t(k)])) ++k;
    uint64_t m = 1;
    unsigned prefix = 1;
    for (int j = k - 2; j >= 0; --j) {
        const int depth = k - 2 - j;
        const unsigned bit = depth < 2 ? rc.decode(c.high[size_t(k)][prefix]) : rc.decode(models.low[size_t(k)][size_t(j)]);
        m = m << 1 | bit;
        if (depth == 0) prefix = 2 + bit;
    }
    return negative ? -int64_t(m) : int64_t(m);
}

// The raster walk shared by both directions. `step(context, prediction,
// sample index)` returns the reconstructed sample.
template <typename Step>
void walk(IntVolumeShape shape, const IntCoderOptions& options, Models& models, Step&& step) {
    const int64_t nx = shape.nx, ny = shape.ny, nz = shape.nz;
    const size_t plane = size_t(nx) * size_t(ny);
    std::vector<int64_t> cur(plane), prev(plane);
    std::vector<SampleRecord> curRec(plane), prevRec(plane);
    const SampleRecord none{};
    // Per row, what the neighbours above and behind contribute to each
    // predictor's error sum (2 N + NE + NW + 2 P + PW + PN) and to the
    // activity (the same of the residuals): summed once per row, in a loop
    // the compiler vectorises; W's part is added per sample.
    std::vector<uint64_t> rowErrors(size_t(nx) * kPredictors);
    std::vector<uint64_t> rowResiduals(static_cast<size_t>(nx));
    for (int64_t z = 0; z < nz; ++z) {
        for (int64_t y = 0; y < ny; ++y) {
            for (int64_t x = 0; x < nx; ++x) {
                const size_t i = size_t(y * nx + x);
                const bool hx = x > 0, hy = y > 0, hz = z > 0, hne = hy && x + 1 < nx;
                const SampleRecord& rN = hy ? curRec[i - size_t(nx)] : none;
                const SampleRecord& rNE = hne ? curRec[i - size_t(nx) + 1] : none;
                const SampleRecord& rNW = hx && hy ? curRec[i - size_t(nx) - 1] : none;
                const SampleRecord& rP = hz ? prevRec[i] : none;
                const SampleRecord& rPW = hz && hx ? prevRec[i - 1] : none;
                const SampleRecord& rPN = hz && hy ? prevRec[i - size_t(nx)] : none;
                for (size_t k = 0; k < kPredictors; ++k)
                    rowErrors[size_t(x) * kPredictors + k] = 2 * (uint64_t(rN.err[k]) + rP.err[k]) + rNE.err[k] + rNW.err[k] + rPW.err[k] + rPN.err[k];
                rowResiduals[size_t(x)] = 2 * (uint64_t(rN.residual) + rP.residual) + rNE.residual + rNW.residual + rPW.residual + rPN.residual;
            }
            for (int64_t x = 0; x < nx; ++x) {
                const size_t i = size_t(y * nx + x);
                // Neighbours, with the nearest coded one where the volume ends.
                const bool hx = x > 0, hy = y > 0, hz = z > 0, hne = hy && x + 1 < nx;
                const int64_t W = hx ? cur[i - 1] : hy ? cur[i - size_t(nx)] : hz ? prev[i] : 0;
                const int64_t N = hy ? cur[i - size_t(nx)] : W;
                const int64_t NW = hx && hy ? cur[i - size_t(nx) - 1] : N;
                const int64_t NE = hne ? cur[i - size_t(nx) + 1] : N;
                const int64_t inPlane = med(W, N, NW);
                int64_t P, PW, PN, PNW;
                if (hz) {
                    P = prev[i];
                    PW = hx ? prev[i - 1] : hy ? prev[i - size_t(nx)] : P;
                    PN = hy ? prev[i - size_t(nx)] : PW;
                    PNW = hx && hy ? prev[i - size_t(nx) - 1] : PN;
                } else {
                    P = inPlane, PW = W, PN = N, PNW = NW;
                }
                std::array<int64_t, kPredictors> p{inPlane, W + N + P - NW - PW - PN + PNW, P + inPlane - med(PW, PN, PNW), W + NE - N, N + P - PN, W + P - PW};
                for (int64_t& q : p) q = std::clamp(q, options.minValue, options.maxValue);  // a prediction outside the range helps no one
                const SampleRecord& rW = hx ? curRec[i - 1] : none;
                const SampleRecord& rN = hy ? curRec[i - size_t(nx)] : none;
                const SampleRecord& rP = hz ? prevRec[i] : none;
                const uint64_t* above = &rowErrors[size_t(x) * kPredictors];
                int64_t weightSum = 0, weighted = 0;  // |weighted| < 6 x (2^26 + 1) x 2^31 < 2^60
                for (int k = 0; k < kPredictors; ++k) {
                    const uint64_t errors = (above[k] + 2 * uint64_t(rW.err[size_t(k)])) / 2;  // 2 (W + N + P) + NE + NW + PW + PN, halved
                    const int64_t w = weightOf(errors);
                    weightSum += w;
                    weighted += w * p[size_t(k)];
                }
                int64_t blend = divRound(weighted, weightSum);
                blend = std::clamp(blend, std::min({W, N, NE, P}), std::max({W, N, NE, P}));
                const uint64_t gradient = uint64_t(std::abs(W - NW) + std::abs(N - NW) + std::abs(NE - N) + std::abs(P - med(PW, PN, PNW)));
                const uint64_t activity = (rowResiduals[size_t(x)] + 2 * uint64_t(rW.residual)) / 2 + gradient / 2;
                const int length = 64 - std::countl_zero(activity);
                const int context = std::min(kContexts - 1, 2 * length + (length >= 2 ? int(activity >> (length - 2)) & 1 : 0));
                ContextModels& c = models.ctx[size_t(context)];
                const int64_t bias = c.biasCount ? divRound(c.biasSum, c.biasCount) : 0;
                const int64_t prediction = std::clamp(blend + bias, options.minValue, options.maxValue);
                const unsigned signs = unsigned(9 * (rP.sign + 1) + 3 * (rW.sign + 1) + (rN.sign + 1));
                const int64_t value = step(c, signs, prediction, size_t(z) * plane + i);
                // What the neighbours will learn from this sample.
                SampleRecord& r = curRec[i];
                for (int k = 0; k < kPredictors; ++k) r.err[size_t(k)] = saturate(std::abs(p[size_t(k)] - value));
                r.residual = saturate(std::abs(value - prediction));
                r.sign = int8_t((value > prediction) - (value < prediction));
                c.biasSum += value - blend;
                if (++c.biasCount == kBiasWindow) {
                    c.biasSum = divRound(c.biasSum, 2);
                    c.biasCount /= 2;
                }
                cur[i] = value;
            }
        }
        std::swap(cur, prev);
        std::swap(curRec, prevRec);
    }
}

// Lossless residuals modulo the range R = maxValue - minValue + 1, into
// [-R/2, R/2) (JPEG-LS's modulo reduction): a residual never needs more bits
// than the samples, so noise costs no more than its bit depth.
int64_t wrap(int64_t e, const IntCoderOptions& o) {
    const int64_t range = o.maxValue - o.minValue + 1;
    if (e < -range / 2) e += range;
    else if (e >= range - range / 2) e -= range;
    return e;
}

// The sample the decoder rebuilds: lossless, the prediction plus the
// residual brought back into the range; near-lossless, the quantised
// residual's centre, clamped (which only brings it closer to the sample).
int64_t reconstruct(int64_t prediction, int64_t q, int64_t step, const IntCoderOptions& o) {
    if (step == 1) {
        const int64_t range = o.maxValue - o.minValue + 1;
        int64_t v = prediction + q;
        if (v < o.minValue) v += range;
        else if (v > o.maxValue) v -= range;
        return std::clamp(v, o.minValue, o.maxValue);  // only a corrupt stream needs the clamp
    }
    return std::clamp(prediction + q * step, o.minValue, o.maxValue);
}

void checkOptions(IntVolumeShape shape, const IntCoderOptions& options) {
    if (shape.nx < 0 || shape.ny < 0 || shape.nz < 0) throw Error("value coder: a negative extent");
    if (options.minValue > options.maxValue || options.minValue < INT32_MIN || options.maxValue > INT32_MAX)
        throw Error("value coder: the sample range must be a non-empty part of int32");
    if (options.near < 0 || options.near > 1 << 20) throw Error("value coder: near must lie in 0..2^20");
}

} // namespace

std::vector<uint8_t> encodeIntVolume(std::span<const int32_t> samples, IntVolumeShape shape, const IntCoderOptions& options,
                                     std::vector<int32_t>* reconstructed) {
    checkOptions(shape, options);
    if (samples.size() != shape.count()) throw Error("value coder: " + std::to_string(samples.size()) + " samples for " + std::to_string(shape.count()));
    std::vector<uint8_t> out;
    RangeEncoder rc(out);
    auto models = std::make_unique<Models>();
    const int64_t step = 2 * int64_t(options.near) + 1;
    if (reconstructed) reconstructed->resize(samples.size());
    walk(shape, options, *models, [&](ContextModels& c, unsigned signs, int64_t prediction, size_t at) {
        const int64_t s = samples[at];
        if (s < options.minValue || s > options.maxValue)
            throw Error("value coder: sample " + std::to_string(s) + " lies outside " + std::to_string(options.minValue) + ".." + std::to_string(options.maxValue));
        const int64_t e = s - prediction;
        const int64_t q = options.near == 0 ? wrap(e, options) : (e >= 0 ? (e + options.near) / step : -((options.near - e) / step));
        putResidual(rc, *models, c, signs, q);
        const int64_t value = reconstruct(prediction, q, step, options);
        if (reconstructed) (*reconstructed)[at] = int32_t(value);
        return value;
    });
    rc.finish();
    return out;
}

void decodeIntVolume(std::span<const uint8_t> bytes, IntVolumeShape shape, const IntCoderOptions& options, std::span<int32_t> out,
                     const std::string& what) {
    checkOptions(shape, options);
    if (out.size() != shape.count()) throw Error(what + ": room for " + std::to_string(out.size()) + " samples, " + std::to_string(shape.count()) + " to decode");
    RangeDecoder rc(bytes);
    auto models = std::make_unique<Models>();
    const int64_t step = 2 * int64_t(options.near) + 1;
    walk(shape, options, *models, [&](ContextModels& c, unsigned signs, int64_t prediction, size_t at) {
        const int64_t q = getResidual(rc, *models, c, signs);
        const int64_t value = reconstruct(prediction, q, step, options);
        out[at] = int32_t(value);
        return value;
    });
    // The encoder's flush leaves at most 4 bytes the decoder never needs
    // and the decoder may look up to 4 bytes past its last one.
    if (rc.overrun() > 4 || rc.consumed() + 4 < bytes.size())
        throw Error(what + ": corrupt (the coded values end " + (rc.overrun() > 4 ? "early" : "before the stream does") + ")");
}

} // namespace vdbdag::coding
