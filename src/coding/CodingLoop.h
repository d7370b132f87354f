// The two directions of a value coder's walk (IntVolumeCoder, BrickValueCoder):
// the walk visits every sample once with its context and prediction and
// asks `step` for the sample's reconstruction; encoding codes the residual
// (lossless modulo the range, or quantised for near-lossless), decoding
// reads it. One loop for both coders, so their streams follow one rule.
#pragma once
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
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

// One sample as the walk leaves it to the range coder: the floor flag's
// model (-1: none) and bit, and the residual with the models that code it.
// The bit models are the range coder's alone (the walk's predictions read
// the fits and bias cells, never a bit model), so the two can run apart.
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

// The encoder's range coding on a thread of its own, fed in chunks by the
// walk (predictions and fits: three quarters of the time), so that a window
// coded while the other cores idle (a grid of one or two windows, a scan's
// last one) takes two. The same bytes as coding each sample in turn.
class PipelinedCoder {
public:
    PipelinedCoder(std::vector<uint8_t>& out, Models& models) : thread_([this, &out, &models] { run(out, models); }) { chunk_.reserve(kChunk); }
    ~PipelinedCoder() {
        if (thread_.joinable()) {  // left by an exception: stop the coder, drop its output
            {
                std::lock_guard lock(mutex_);
                done_ = abort_ = true;
            }
            ready_.notify_all();
            thread_.join();
        }
    }
    void push(const CodedSample& c) {
        chunk_.push_back(c);
        if (chunk_.size() == kChunk) hand();
    }
    // Codes what is left and ends the stream; rethrows the coder's failure.
    void finish() {
        hand();
        {
            std::lock_guard lock(mutex_);
            done_ = true;
        }
        ready_.notify_all();
        thread_.join();
        if (failure_) std::rethrow_exception(failure_);
    }

private:
    static constexpr size_t kChunk = 8192, kInFlight = 4;
    void hand() {
        if (chunk_.empty()) return;
        std::vector<CodedSample> next;
        {
            std::unique_lock lock(mutex_);
            room_.wait(lock, [&] { return full_.size() < kInFlight || abort_; });
            full_.push_back(std::move(chunk_));
            if (!spare_.empty()) next = std::move(spare_.back()), spare_.pop_back();
        }
        ready_.notify_one();
        chunk_ = std::move(next);
        chunk_.reserve(kChunk);
    }
    void run(std::vector<uint8_t>& out, Models& models) {
        try {
            RangeEncoder rc(out);
            for (;;) {
                std::vector<CodedSample> c;
                {
                    std::unique_lock lock(mutex_);
                    ready_.wait(lock, [&] { return !full_.empty() || done_; });
                    if (abort_ || full_.empty()) break;
                    c = std::move(full_.front());
                    full_.pop_front();
                }
                room_.notify_one();
                for (const CodedSample& x : c) codeSample(rc, models, x);
                c.clear();
                std::lock_guard lock(mutex_);
                spare_.push_back(std::move(c));
            }
            std::lock_guard lock(mutex_);
            if (!abort_) rc.finish();
        } catch (...) {
            std::lock_guard lock(mutex_);
            failure_ = std::current_exception();
            abort_ = true;
            room_.notify_all();
        }
    }
    std::vector<CodedSample> chunk_;
    std::mutex mutex_;
    std::condition_variable ready_, room_;
    std::deque<std::vector<CodedSample>> full_;
    std::vector<std::vector<CodedSample>> spare_;
    bool done_ = false, abort_ = false;
    std::exception_ptr failure_;
    std::thread thread_;  // last: started once the rest is built
};

// Below this many samples the encoder codes in the walk's thread (a
// thread's start costs more than it saves).
inline constexpr size_t kPipelinedSamples = size_t(1) << 16;

// `walk(models, step)` runs the walk; step(prediction, index) returns the sample's reconstruction.
template <typename Walk>
std::vector<uint8_t> encodeSamples(std::span<const int32_t> samples, const IntCoderOptions& options, std::vector<int32_t>* reconstructed, Walk&& walk) {
    checkRange(options);
    std::vector<uint8_t> out;
    auto models = std::make_unique<Models>(options.model);
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
    if (!options.codeAside || samples.size() < kPipelinedSamples) {
        RangeEncoder rc(out);
        walk(*models, [&](const Prediction& pr, uint64_t at) { return code(pr, at, [&](const CodedSample& c) { codeSample(rc, *models, c); }); });
        rc.finish();
        return out;
    }
    PipelinedCoder coder(out, *models);
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
