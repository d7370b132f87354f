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
    if (options.model < 0 || options.model > 1) throw Error("value coder: model generation " + std::to_string(options.model) + " (0 or 1)");
}

// `walk(models, step)` runs the walk; step(context, signs, prediction, index).
template <typename Walk>
std::vector<uint8_t> encodeSamples(std::span<const int32_t> samples, const IntCoderOptions& options, std::vector<int32_t>* reconstructed, Walk&& walk) {
    checkRange(options);
    std::vector<uint8_t> out;
    RangeEncoder rc(out);
    auto models = std::make_unique<Models>(options.model);
    const int64_t step = 2 * int64_t(options.near) + 1;
    if (reconstructed) reconstructed->resize(samples.size());
    walk(*models, [&](ContextModels& c, unsigned signs, int64_t prediction, uint64_t at) {
        const int64_t s = samples[at];
        if (s < options.minValue || s > options.maxValue)
            throw Error("value coder: sample " + std::to_string(s) + " lies outside " + std::to_string(options.minValue) + ".." + std::to_string(options.maxValue));
        const int64_t e = s - prediction;
        const int64_t q = options.near == 0 ? wrap(e, options.minValue, options.maxValue) : (e >= 0 ? (e + options.near) / step : -((options.near - e) / step));
        putResidual(rc, *models, c, signs, q);
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
        walk(*models, [&](ContextModels& c, unsigned signs, int64_t prediction, uint64_t at) {
            const int64_t v = reconstruct(prediction, getResidual(rc, *models, c, signs), step, options.minValue, options.maxValue);
            out[at] = int32_t(v);
            return v;
        });
    } catch (const Error& e) {
        throw Error(what + ": " + e.what());
    }
    if (const char* fault = rc.endFault()) throw Error(what + ": corrupt (the coded values end " + fault + ")");
}

} // namespace vdbdag::coding::detail
