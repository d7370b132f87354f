// The two directions of a value coder's walk (IntVolumeCoder, BrickValueCoder):
// the walk visits every sample once with its context and prediction and
// asks `step` for the sample's reconstruction; encoding codes the residual
// (lossless modulo the range, or quantised for near-lossless), decoding
// reads it. One loop for both coders, so their streams follow one rule.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "src/coding/IntVolumeCoder.h"
#include "src/coding/SamplePredictor.h"
#include "src/util/Error.h"

namespace vdbdag::coding::detail {

inline void checkRange(const IntCoderOptions& options) {
    if (options.minValue > options.maxValue || options.minValue < INT32_MIN || options.maxValue > INT32_MAX)
        throw Error("value coder: the sample range must be a non-empty part of int32");
    if (options.near < 0 || options.near > 1 << 20) throw Error("value coder: near must lie in 0..2^20");
    if (options.model < 0 || options.model > kLatestModel)
        throw Error("value coder: model generation " + std::to_string(options.model) + " (0 to " + std::to_string(kLatestModel) + ")");
}

// `walk(models, step)` runs the walk; step(prediction, index) returns the sample's reconstruction.
template <typename Walk>
std::vector<uint8_t> encodeSamples(std::span<const int32_t> samples, const IntCoderOptions& options, std::vector<int32_t>* reconstructed, Walk&& walk) {
    checkRange(options);
    std::vector<uint8_t> out;
    RangeEncoder rc(out);
    auto models = std::make_unique<Models>(options.model);
    const int64_t step = 2 * int64_t(options.near) + 1;
    if (reconstructed) reconstructed->resize(samples.size());
    walk(*models, [&](const Prediction& pr, uint64_t at) {
        const int64_t s = samples[at];
        if (s < options.minValue || s > options.maxValue)
            throw Error("value coder: sample " + std::to_string(s) + " lies outside " + std::to_string(options.minValue) + ".." + std::to_string(options.maxValue));
        if (pr.floor >= 0) {  // generation 2: is it the minimum?
            rc.encode(models->floor[size_t(pr.floor)], s == options.minValue);
            if (s == options.minValue) {
                if (reconstructed) (*reconstructed)[at] = int32_t(s);
                return s;
            }
        }
        const int64_t prediction = pr.value;
        const int64_t e = s - prediction;
        const int64_t q = options.near == 0 ? wrap(e, options.minValue, options.maxValue) : (e >= 0 ? (e + options.near) / step : -((options.near - e) / step));
        putResidual(rc, *models, *pr.ctx, *pr.high, pr.signs, q);
        const int64_t v = reconstruct(prediction, q, step, options.minValue, options.maxValue);
        if (reconstructed) (*reconstructed)[at] = int32_t(v);
        return v;
    });
    rc.finish();
    return out;
}

// Throws vdbdag::Error naming `what` when the walk refuses its input or the
// stream ends early or carries bytes it does not use.
template <typename Walk>
void decodeSamples(std::span<const uint8_t> bytes, const IntCoderOptions& options, std::span<int32_t> out, const std::string& what, Walk&& walk) {
    checkRange(options);
    RangeDecoder rc(bytes);
    auto models = std::make_unique<Models>(options.model);
    const int64_t step = 2 * int64_t(options.near) + 1;
    try {
        walk(*models, [&](const Prediction& pr, uint64_t at) {
            if (pr.floor >= 0 && rc.decode(models->floor[size_t(pr.floor)])) {
                out[at] = int32_t(options.minValue);
                return options.minValue;
            }
            const int64_t v = reconstruct(pr.value, getResidual(rc, *models, *pr.ctx, *pr.high, pr.signs), step, options.minValue, options.maxValue);
            out[at] = int32_t(v);
            return v;
        });
    } catch (const Error& e) {
        throw Error(what + ": " + e.what());
    }
    if (const char* fault = rc.endFault()) throw Error(what + ": corrupt (the coded values end " + fault + ")");
}

} // namespace vdbdag::coding::detail
