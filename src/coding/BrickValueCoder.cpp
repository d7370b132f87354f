// See BrickValueCoder.h. One template walks the entries for both
// directions, as IntVolumeCoder.cpp does.
#include "src/coding/BrickValueCoder.h"

#include <bit>
#include <memory>

#include "src/coding/SamplePredictor.h"
#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

using namespace detail;

// `step(context, signs, prediction, entry)` returns the reconstructed entry.
template <typename Step>
void walk(std::span<const uint64_t> layout, uint64_t entries, const IntCoderOptions& options, Models& models, Step&& step) {
    int64_t value[64];
    SampleRecord rec[64];
    int64_t last = 0;         // the previous entry in attribute order
    SampleRecord lastRec{};   // and its record
    uint64_t e = 0;
    const auto code = [&](Neighbourhood& n) {
        const Prediction pr = predict(n, options.minValue, options.maxValue, models);
        const int64_t v = step(*pr.ctx, pr.signs, pr.value, e++);
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

void checkOptions(const IntCoderOptions& options) {
    if (options.minValue > options.maxValue || options.minValue < INT32_MIN || options.maxValue > INT32_MAX)
        throw Error("value coder: the sample range must be a non-empty part of int32");
    if (options.near < 0 || options.near > 1 << 20) throw Error("value coder: near must lie in 0..2^20");
}

} // namespace

uint64_t layoutEntryCount(std::span<const uint64_t> layout) {
    uint64_t n = 0;
    for (const uint64_t mask : layout) n += mask ? uint64_t(std::popcount(mask)) : 1;
    return n;
}

std::vector<uint8_t> encodeBrickValues(std::span<const int32_t> entries, std::span<const uint64_t> layout, const IntCoderOptions& options,
                                       std::vector<int32_t>* reconstructed) {
    checkOptions(options);
    std::vector<uint8_t> out;
    RangeEncoder rc(out);
    auto models = std::make_unique<Models>();
    const int64_t step = 2 * int64_t(options.near) + 1;
    if (reconstructed) reconstructed->resize(entries.size());
    walk(layout, entries.size(), options, *models, [&](ContextModels& c, unsigned signs, int64_t prediction, uint64_t at) {
        const int64_t s = entries[at];
        if (s < options.minValue || s > options.maxValue)
            throw Error("value coder: entry " + std::to_string(s) + " lies outside " + std::to_string(options.minValue) + ".." + std::to_string(options.maxValue));
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

void decodeBrickValues(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, const IntCoderOptions& options, std::span<int32_t> out,
                       const std::string& what) {
    checkOptions(options);
    RangeDecoder rc(bytes);
    auto models = std::make_unique<Models>();
    const int64_t step = 2 * int64_t(options.near) + 1;
    try {
        walk(layout, out.size(), options, *models, [&](ContextModels& c, unsigned signs, int64_t prediction, uint64_t at) {
            const int64_t v = reconstruct(prediction, getResidual(rc, *models, c, signs), step, options.minValue, options.maxValue);
            out[at] = int32_t(v);
            return v;
        });
    } catch (const Error& e) {
        throw Error(what + ": " + e.what());
    }
    // As IntVolumeCoder: at most 4 bytes of the flush unread, at most 4 read past the end.
    if (rc.overrun() > 4 || rc.consumed() + 4 < bytes.size())
        throw Error(what + ": corrupt (the coded values end " + (rc.overrun() > 4 ? "early" : "before the stream does") + ")");
}

} // namespace vdbdag::coding
