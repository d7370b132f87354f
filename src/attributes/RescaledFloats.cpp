// See RescaledFloats.h.
#include "src/attributes/RescaledFloats.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "src/attributes/ContextChannel.h"
#include "src/format/ByteIO.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {
namespace {

constexpr size_t kHeaderBytes = 8 + 8 + 4;

// The integer whose lattice value has `v`'s bits, if any: the nearest to
// (v - intercept) / slope, or a neighbour of it (float rounding can make
// several integers give one value, or move the quotient across a half).
std::optional<int32_t> latticeIndex(float v, const ValueRescale& r) {
    const double q = std::nearbyint((double(v) - r.intercept) / r.slope);
    if (!(q >= double(INT32_MIN) + 1 && q <= double(INT32_MAX) - 1)) return std::nullopt;  // NaN too
    const uint32_t bits = std::bit_cast<uint32_t>(v);
    for (const int64_t k : {int64_t(q), int64_t(q) - 1, int64_t(q) + 1})
        if (std::bit_cast<uint32_t>(rescaledFloat(k, r)) == bits) return int32_t(k);
    return std::nullopt;
}

} // namespace

std::vector<int32_t> referenceIntegers(std::span<const uint8_t> reference, const ValueRescale& rescale) {
    std::vector<int32_t> out(reference.size() / 4);
    for (size_t i = 0; i < out.size(); ++i) {
        float v;
        std::memcpy(&v, reference.data() + 4 * i, 4);
        const double q = std::nearbyint((double(v) - rescale.intercept) / rescale.slope);
        out[i] = q != q ? 0 : int32_t(std::clamp(q, double(INT32_MIN) + 1, double(INT32_MAX) - 1));
    }
    return out;
}

std::optional<std::vector<uint8_t>> encodeRescaledFloats(std::span<const uint8_t> values, std::span<const uint64_t> layout,
                                                         std::span<const coding::BrickPlace> places, const ValueRescale& rescale, int model,
                                                         bool tileNeighbours, bool codeAside, std::span<const uint8_t> reference) {
    if (values.size() % 4) throw Error("internal error: rescaled floats are 4-byte entries");
    if (!std::isfinite(rescale.slope) || rescale.slope == 0 || !std::isfinite(rescale.intercept)) return std::nullopt;
    const size_t n = values.size() / 4;
    std::vector<int32_t> integers(n);
    std::vector<std::pair<uint32_t, uint32_t>> exceptions;  // (index, bits)
    int32_t last = 0;
    for (size_t i = 0; i < n; ++i) {
        float v;
        std::memcpy(&v, values.data() + 4 * i, 4);
        if (const std::optional<int32_t> k = latticeIndex(v, rescale)) {
            integers[i] = last = *k;
            continue;
        }
        integers[i] = last;
        exceptions.emplace_back(uint32_t(i), std::bit_cast<uint32_t>(v));
        if (exceptions.size() > n / 16) return std::nullopt;
    }
    const std::vector<uint8_t> coded = encodeContextChannel(
        std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(integers.data()), integers.size() * 4), layout, places, false,
        coding::spatialOrderOf(model), model, 1, tileNeighbours, codeAside, reference.empty() ? std::vector<int32_t>{} : referenceIntegers(reference, rescale));
    format::ByteWriter w;
    w.bytes().reserve(kHeaderBytes + 8 * exceptions.size() + coded.size());
    w.put(rescale.slope);
    w.put(rescale.intercept);
    w.put(uint32_t(exceptions.size()));
    for (const auto& [index, bits] : exceptions) {
        w.put(index);
        w.put(bits);
    }
    w.putBytes(coded);
    return w.take();
}

std::vector<uint8_t> decodeRescaledFloats(std::span<const uint8_t> payload, std::span<const uint64_t> layout, uint64_t entries, const std::string& what,
                                          std::span<const coding::BrickPlace> places, int model, bool tileNeighbours, std::span<const uint8_t> reference) {
    format::ByteReader r(payload, what);
    ValueRescale rescale;
    rescale.slope = r.get<double>();
    rescale.intercept = r.get<double>();
    if (!std::isfinite(rescale.slope) || rescale.slope == 0 || !std::isfinite(rescale.intercept)) r.fail("a rescale that is not finite or has slope 0");
    const uint32_t count = r.get<uint32_t>();
    if (count > entries || count > r.remaining() / 8) r.fail(std::to_string(count) + " exceptions (more than its entries or bytes)");
    std::vector<std::pair<uint32_t, uint32_t>> exceptions(count);
    for (uint32_t j = 0; j < count; ++j) {
        exceptions[j].first = r.get<uint32_t>();
        exceptions[j].second = r.get<uint32_t>();
        if (exceptions[j].first >= entries || (j && exceptions[j].first <= exceptions[j - 1].first))
            r.fail("its exceptions are not in increasing entry order inside the window");
    }
    std::vector<uint8_t> out =
        decodeContextChannel(payload.subspan(r.position()), layout, entries, what, places, false, coding::spatialOrderOf(model), model, 1, tileNeighbours,
                             reference.empty() ? std::vector<int32_t>{} : referenceIntegers(reference, rescale));
    for (size_t i = 0; i + 4 <= out.size(); i += 4) {
        int32_t k;
        std::memcpy(&k, out.data() + i, 4);
        const float v = rescaledFloat(k, rescale);
        std::memcpy(out.data() + i, &v, 4);
    }
    for (const auto& [index, bits] : exceptions) std::memcpy(out.data() + 4 * size_t(index), &bits, 4);
    return out;
}

} // namespace vdbdag::attributes
