// The two directions of a value coder's walk (IntVolumeCoder, BrickValueCoder):
// the walk visits every sample once with its context and prediction and
// asks `step` for the sample's reconstruction; encoding codes the residual
// (lossless modulo the range, or quantised for near-lossless), decoding
// reads it. One loop for both coders, so their streams follow one rule.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/coding/CodeAside.h"
#include "src/coding/IntVolumeCoder.h"
#include "src/coding/SamplePredictor.h"
#include "src/coding/ThreadLease.h"
#include "src/util/Error.h"

namespace vdbdag::coding::detail {

inline void checkRange(const IntCoderOptions& options) {
    if (options.minValue > options.maxValue || options.minValue < INT32_MIN || options.maxValue > INT32_MAX)
        throw Error("value coder: the sample range must be a non-empty part of int32");
    if (options.near < 0 || options.near > 1 << 20) throw Error("value coder: near must lie in 0..2^20");
    if (options.model < 0 || options.model > kLatestModel)
        throw Error("value coder: model generation " + std::to_string(options.model) + " (0 to " + std::to_string(kLatestModel) + ")");
}

// The models of one walk, kept per thread and generation (ThreadLease.h).
class ModelsLease : public ThreadLease<Models, kLatestModel + 1> {
public:
    explicit ModelsLease(int generation) : ThreadLease(size_t(generation), generation) {}
};

// One sample as the walk leaves it to the range coder: the floor flag's
// model (-1: none) and bit, and the residual with the models that code it
// (CodeAside.h: the predictions read the fits and bias cells, never a bit
// model).
struct CodedSample {
    ContextModels* ctx;
    ContextModels* high;
    int64_t q;
    int32_t floor;
    uint8_t signs;
    uint8_t isFloor;  // the sample is the minimum: the flag says so, no residual
};

inline void codeSample(RangeEncoder& rc, Models& models, const CodedSample& c) {
    if (c.floor >= 0) rc.encode(models.floor[size_t(c.floor)], c.isFloor);
    if (!c.isFloor) putResidual(rc, models, *c.ctx, *c.high, c.signs, c.q);
}

// `walk(models, step)` runs the walk; step(prediction, index) returns the sample's reconstruction.
template <typename Walk>
std::vector<uint8_t> encodeSamples(std::span<const int32_t> samples, const IntCoderOptions& options, std::vector<int32_t>* reconstructed, Walk&& walk) {
    checkRange(options);
    std::vector<uint8_t> out;
    const ModelsLease models(options.model);
    const int64_t step = 2 * int64_t(options.near) + 1;
    if (reconstructed) reconstructed->resize(samples.size());
    const auto code = [&](const Prediction& pr, uint64_t at, auto&& emit) {
        const int64_t s = samples[at];
        if (s < options.minValue || s > options.maxValue)
            throw Error("value coder: sample " + std::to_string(s) + " lies outside " + std::to_string(options.minValue) + ".." + std::to_string(options.maxValue));
        CodedSample c{pr.ctx, pr.high, 0, int32_t(pr.floor), uint8_t(pr.signs), 0};
        if (pr.floor >= 0 && s == options.minValue) {  // generation 2: the minimum, said by its flag
            c.isFloor = 1;
            emit(c);
            if (reconstructed) (*reconstructed)[at] = int32_t(s);
            return s;
        }
        const int64_t prediction = pr.value;
        const int64_t e = s - prediction;
        c.q = options.near == 0 ? wrap(e, options.minValue, options.maxValue) : (e >= 0 ? (e + options.near) / step : -((options.near - e) / step));
        emit(c);
        const int64_t v = reconstruct(prediction, c.q, step, options.minValue, options.maxValue);
        if (reconstructed) (*reconstructed)[at] = int32_t(v);
        return v;
    };
    if (!options.codeAside || samples.size() < kCodeAsideSamples) {
        RangeEncoder rc(out);
        walk(*models, [&](const Prediction& pr, uint64_t at) { return code(pr, at, [&](const CodedSample& c) { codeSample(rc, *models, c); }); });
        rc.finish();
        return out;
    }
    CodeAside<CodedSample> coder(out, [&models](RangeEncoder& rc, std::span<const CodedSample> items) {
        for (const CodedSample& c : items) codeSample(rc, *models, c);
    });
    walk(*models, [&](const Prediction& pr, uint64_t at) { return code(pr, at, [&](const CodedSample& c) { coder.push(c); }); });
    coder.finish();
    return out;
}

// Throws vdbdag::Error naming `what` when the walk refuses its input or the
// stream ends early or carries bytes it does not use.
template <typename Walk>
void decodeSamples(std::span<const uint8_t> bytes, const IntCoderOptions& options, std::span<int32_t> out, const std::string& what, Walk&& walk) {
    checkRange(options);
    RangeDecoder rc(bytes);
    const ModelsLease models(options.model);
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
