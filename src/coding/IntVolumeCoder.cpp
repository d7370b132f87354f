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
#include "src/coding/SamplePredictor.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using namespace detail;

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
                Neighbourhood n;
                n.W = hx ? cur[i - 1] : hy ? cur[i - size_t(nx)] : hz ? prev[i] : 0;
                n.N = hy ? cur[i - size_t(nx)] : n.W;
                n.NW = hx && hy ? cur[i - size_t(nx) - 1] : n.N;
                n.NE = hne ? cur[i - size_t(nx) + 1] : n.N;
                if (hz) {
                    n.P = prev[i];
                    n.PW = hx ? prev[i - 1] : hy ? prev[i - size_t(nx)] : n.P;
                    n.PN = hy ? prev[i - size_t(nx)] : n.PW;
                    n.PNW = hx && hy ? prev[i - size_t(nx) - 1] : n.PN;
                } else {
                    n.P = med(n.W, n.N, n.NW), n.PW = n.W, n.PN = n.N, n.PNW = n.NW;
                }
                n.rW = hx ? &curRec[i - 1] : nullptr;
                n.rN = hy ? &curRec[i - size_t(nx)] : nullptr;
                n.rP = hz ? &prevRec[i] : nullptr;
                std::copy_n(&rowErrors[size_t(x) * kPredictors], kPredictors, n.errorsAbove.begin());
                n.residualsAbove = rowResiduals[size_t(x)];
                const Prediction pr = predict(n, options.minValue, options.maxValue, models);
                const int64_t value = step(*pr.ctx, pr.signs, pr.value, size_t(z) * plane + i);
                learn(pr, value, curRec[i]);
                cur[i] = value;
            }
        }
        std::swap(cur, prev);
        std::swap(curRec, prevRec);
    }
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
        const int64_t q = options.near == 0 ? wrap(e, options.minValue, options.maxValue) : (e >= 0 ? (e + options.near) / step : -((options.near - e) / step));
        putResidual(rc, *models, c, signs, q);
        const int64_t value = reconstruct(prediction, q, step, options.minValue, options.maxValue);
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
        const int64_t value = reconstruct(prediction, q, step, options.minValue, options.maxValue);
        out[at] = int32_t(value);
        return value;
    });
    // The encoder's flush leaves at most 4 bytes the decoder never needs
    // and the decoder may look up to 4 bytes past its last one.
    if (rc.overrun() > 4 || rc.consumed() + 4 < bytes.size())
        throw Error(what + ": corrupt (the coded values end " + (rc.overrun() > 4 ? "early" : "before the stream does") + ")");
}

} // namespace vdbdag::coding
