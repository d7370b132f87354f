// See ContextChannel.h.
#include "src/attributes/ContextChannel.h"

#include <algorithm>
#include <numeric>
#include <cstring>

#include "src/coding/BrickValueCoder.h"
#include "src/coding/LabelCoder.h"
#include "src/format/ByteIO.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {
namespace {
constexpr size_t kHeaderBytes = 1 + 4 + 4 + 4 + 4 + 8;
// The model generation of a window's coding (coding/IntVolumeCoder.h):
// `spatial` (1 or 2, the window's coding says which) for bricks in spatial
// order, 0 for the codings before (2, 3).
int modelOf(std::span<const coding::BrickPlace> places, coding::BrickOrder order, int spatial) {
    if (spatial < 1 || spatial > coding::kLatestIntModel) throw Error("internal error: model generation " + std::to_string(spatial));
    return !places.empty() && order != coding::BrickOrder::Attribute ? spatial : 0;
}
// A reference's entries as the coder sees the entries: (t - lo) / step,
// rounded down (an entry off the step's lattice is a tap all the same).
std::vector<int32_t> referenceTaps(std::span<const int32_t> reference, int32_t lo, uint64_t step) {
    std::vector<int32_t> taps(reference.begin(), reference.end());
    if (step > 1)
        for (int32_t& t : taps) {
            const int64_t d = int64_t(t) - lo, s = int64_t(step);
            t = int32_t(d >= 0 ? d / s : -((-d + s - 1) / s));
        }
    return taps;
}
void checkReference(std::span<const int32_t> reference, bool labels, std::span<const coding::BrickPlace> places, int model, size_t entries,
                    const std::string& what) {
    if (reference.empty()) return;
    if (labels || places.empty() || model < 3) throw Error(what + ": internal error: a reference needs a placed walk of generation 3 or later");
    if (reference.size() != entries)
        throw Error(what + ": a reference of " + std::to_string(reference.size()) + " entries for " + std::to_string(entries));
}
} // namespace

std::vector<uint8_t> encodeContextChannel(std::span<const uint8_t> values, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places,
                                          bool labels, coding::BrickOrder order, int model, int labelModel, bool tileNeighbours, bool codeAside,
                                          std::span<const int32_t> reference) {
    if (labels && places.empty()) throw Error("internal error: labels are coded with their bricks' places");
    if (values.size() % 4) throw Error("internal error: a context-coded channel holds int32 entries");
    std::vector<int32_t> entries(values.size() / 4);
    std::memcpy(entries.data(), values.data(), values.size());
    int32_t lo = 0, hi = 0;
    if (!entries.empty()) {
        const auto [min, max] = std::minmax_element(entries.begin(), entries.end());
        lo = *min, hi = *max;
    }
    // The entries' common step above the minimum (values quantised by
    // --abs-error, or a scanner's): the coder sees (v - min) / step.
    uint64_t step = 0;
    for (const int32_t v : entries) step = std::gcd(step, uint64_t(int64_t(v) - lo));
    if (step == 0) step = 1;
    if (step > 1)
        for (int32_t& v : entries) v = int32_t((int64_t(v) - lo) / int64_t(step));
    coding::IntCoderOptions options;
    options.minValue = step > 1 ? 0 : lo;
    options.maxValue = step > 1 ? (int64_t(hi) - lo) / int64_t(step) : hi;
    options.model = modelOf(places, order, model);
    options.tileNeighbours = tileNeighbours;
    options.codeAside = codeAside;
    checkReference(reference, labels, places, options.model, entries.size(), "value coder");
    const std::vector<int32_t> taps = referenceTaps(reference, lo, step);
    options.reference = taps;
    const std::vector<uint8_t> stream =
        labels           ? coding::encodePlacedLabels(entries, layout, places, order, int32_t(options.minValue), int32_t(options.maxValue), labelModel)
        : places.empty() ? coding::encodeBrickValues(entries, layout, options)
                         : coding::encodePlacedBrickValues(entries, layout, places, order, options);
    // The header (ContextChannel.h) then the stream, in one allocation.
    std::vector<uint8_t> out(kHeaderBytes + stream.size());
    size_t at = 0;
    const auto put = [&](auto v) {
        std::memcpy(out.data() + at, &v, sizeof v);
        at += sizeof v;
    };
    put(uint8_t(4)), put(uint32_t(options.near)), put(uint32_t(step)), put(lo), put(hi), put(uint64_t(entries.size()));
    std::copy(stream.begin(), stream.end(), out.begin() + ptrdiff_t(at));
    return out;
}

std::vector<uint8_t> decodeContextChannel(std::span<const uint8_t> payload, std::span<const uint64_t> layout, uint64_t entries, const std::string& what,
                                          std::span<const coding::BrickPlace> places, bool labels, coding::BrickOrder order, int model,
                                          int labelModel, bool tileNeighbours, std::span<const int32_t> reference) {
    format::ByteReader r(payload, what);
    const uint8_t valueSize = r.get<uint8_t>();
    if (valueSize != 4) r.fail("a context-coded channel of " + std::to_string(valueSize) + "-byte values (4 expected)");
    coding::IntCoderOptions options;
    options.model = modelOf(places, order, model);
    options.tileNeighbours = tileNeighbours;
    if (tileNeighbours && (labels || places.empty() || options.model != 4)) r.fail("internal error: tiles as neighbours need a placed walk of generation 4");
    const uint32_t near = r.get<uint32_t>();
    if (near > (1u << 20)) r.fail("a near-lossless bound of " + std::to_string(near) + " (at most 2^20)");
    options.near = int32_t(near);
    const uint32_t step = r.get<uint32_t>();
    const int32_t lo = r.get<int32_t>(), hi = r.get<int32_t>();
    if (lo > hi) r.fail("its value range is empty");
    if (step == 0 || (int64_t(hi) - lo) % step) r.fail("a step of " + std::to_string(step) + " that does not divide its value range");
    options.minValue = step > 1 ? 0 : lo;
    options.maxValue = step > 1 ? (int64_t(hi) - lo) / step : hi;
    const uint64_t n = r.get<uint64_t>();
    if (n != entries || coding::layoutEntryCount(layout) != entries)
        r.fail("holds " + std::to_string(n) + " entries, its bricks " + std::to_string(coding::layoutEntryCount(layout)) + ", expected " + std::to_string(entries));
    std::vector<int32_t> decoded(static_cast<size_t>(entries));
    if (labels && (near || places.empty())) r.fail("labels coded near-lossless or without places");
    checkReference(reference, labels, places, options.model, decoded.size(), what);
    const std::vector<int32_t> taps = referenceTaps(reference, lo, step);
    options.reference = taps;
    if (labels)
        coding::decodePlacedLabels(payload.subspan(kHeaderBytes), layout, places, order, int32_t(options.minValue), int32_t(options.maxValue), decoded, what,
                                   labelModel);
    else if (places.empty()) coding::decodeBrickValues(payload.subspan(kHeaderBytes), layout, options, decoded, what);
    else coding::decodePlacedBrickValues(payload.subspan(kHeaderBytes), layout, places, order, options, decoded, what);
    if (step > 1)
        for (int32_t& v : decoded) v = int32_t(lo + int64_t(v) * step);
    std::vector<uint8_t> out(decoded.size() * 4);
    std::memcpy(out.data(), decoded.data(), out.size());
    return out;
}

} // namespace vdbdag::attributes
