// See ContextChannel.h.
#include "src/attributes/ContextChannel.h"

#include <algorithm>
#include <cstring>

#include "src/coding/BrickValueCoder.h"
#include "src/format/ByteIO.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {
namespace {
constexpr size_t kHeaderBytes = 1 + 4 + 4 + 4 + 8;
} // namespace

std::vector<uint8_t> encodeContextChannel(std::span<const uint8_t> values, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places) {
    if (values.size() % 4) throw Error("internal error: a context-coded channel holds int32 entries");
    std::vector<int32_t> entries(values.size() / 4);
    std::memcpy(entries.data(), values.data(), values.size());
    coding::IntCoderOptions options;
    if (!entries.empty()) {
        const auto [lo, hi] = std::minmax_element(entries.begin(), entries.end());
        options.minValue = *lo, options.maxValue = *hi;
    } else {
        options.minValue = options.maxValue = 0;
    }
    const std::vector<uint8_t> stream =
        places.empty() ? coding::encodeBrickValues(entries, layout, options) : coding::encodePlacedBrickValues(entries, layout, places, options);
    format::ByteWriter w;
    w.put<uint8_t>(4);
    w.put<uint32_t>(uint32_t(options.near));
    w.put<int32_t>(int32_t(options.minValue));
    w.put<int32_t>(int32_t(options.maxValue));
    w.put<uint64_t>(entries.size());
    w.putBytes(stream);
    return std::move(w.bytes());
}

std::vector<uint8_t> decodeContextChannel(std::span<const uint8_t> payload, std::span<const uint64_t> layout, uint64_t entries, const std::string& what,
                                          std::span<const coding::BrickPlace> places) {
    format::ByteReader r(payload, what);
    const uint8_t valueSize = r.get<uint8_t>();
    if (valueSize != 4) r.fail("a context-coded channel of " + std::to_string(valueSize) + "-byte values (4 expected)");
    coding::IntCoderOptions options;
    const uint32_t near = r.get<uint32_t>();
    if (near > (1u << 20)) r.fail("a near-lossless bound of " + std::to_string(near) + " (at most 2^20)");
    options.near = int32_t(near);
    options.minValue = r.get<int32_t>();
    options.maxValue = r.get<int32_t>();
    if (options.minValue > options.maxValue) r.fail("its value range is empty");
    const uint64_t n = r.get<uint64_t>();
    if (n != entries || coding::layoutEntryCount(layout) != entries)
        r.fail("holds " + std::to_string(n) + " entries, its bricks " + std::to_string(coding::layoutEntryCount(layout)) + ", expected " + std::to_string(entries));
    std::vector<int32_t> decoded(static_cast<size_t>(entries));
    if (places.empty()) coding::decodeBrickValues(payload.subspan(kHeaderBytes), layout, options, decoded, what);
    else coding::decodePlacedBrickValues(payload.subspan(kHeaderBytes), layout, places, options, decoded, what);
    std::vector<uint8_t> out(decoded.size() * 4);
    std::memcpy(out.data(), decoded.data(), out.size());
    return out;
}

} // namespace vdbdag::attributes
