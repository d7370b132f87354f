// See FloatIntegerCoder.h.
#include "src/coding/FloatIntegerCoder.h"

#include <algorithm>
#include <bit>
#include <climits>

#include "src/util/Error.h"

namespace vdbdag::coding {
namespace {

// The header's generation: 0, the integers coded by model generation 2
// (written 2026-12-05 to 2026-12-06); 1, by generation 3 (written on
// 2026-12-06); 2, by generation 4 (what is written).
constexpr uint8_t kGeneration = 2;
constexpr size_t kHeaderBytes = 10;  // generation, shift, min, max

IntCoderOptions optionsFor(int32_t lo, int32_t hi, uint8_t generation) {
    IntCoderOptions o;
    o.minValue = lo, o.maxValue = hi, o.model = generation + 2;
    return o;
}

void putI32(std::vector<uint8_t>& out, int32_t v) {
    for (int b = 0; b < 4; ++b) out.push_back(uint8_t(uint32_t(v) >> (8 * b)));
}
int32_t getI32(const uint8_t* p) { return int32_t(uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24); }

} // namespace

unsigned floatZeroLowBits(std::span<const uint32_t> bits) {
    uint32_t any = 0;
    for (const uint32_t b : bits) any |= b & 0x7FFFFFFFu;
    return any ? unsigned(std::countr_zero(any)) : 31u;
}

std::vector<uint8_t> encodePlacedFloatIntegers(std::span<const uint32_t> bits, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                                               bool codeAside) {
    const unsigned shift = floatZeroLowBits(bits);
    std::vector<int32_t> ints(bits.size());
    int32_t lo = INT32_MAX, hi = INT32_MIN;
    for (size_t i = 0; i < bits.size(); ++i) {
        const int32_t m = int32_t((bits[i] & 0x7FFFFFFFu) >> shift);
        ints[i] = (bits[i] >> 31) ? -1 - m : m;
        lo = std::min(lo, ints[i]), hi = std::max(hi, ints[i]);
    }
    if (ints.empty()) lo = hi = 0;
    std::vector<uint8_t> out{kGeneration, uint8_t(shift)};
    putI32(out, lo);
    putI32(out, hi);
    IntCoderOptions options = optionsFor(lo, hi, kGeneration);
    options.codeAside = codeAside;
    const std::vector<uint8_t> stream = encodePlacedBrickValues(ints, layout, places, BrickOrder::Raster, options);
    out.insert(out.end(), stream.begin(), stream.end());
    return out;
}

void decodePlacedFloatIntegers(std::span<const uint8_t> payload, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                               std::span<uint32_t> out, const std::string& what) {
    if (payload.size() < kHeaderBytes) throw Error(what + ": float integers: " + std::to_string(payload.size()) + " bytes, shorter than their header");
    if (payload[0] > kGeneration) throw Error(what + ": float integers of generation " + std::to_string(payload[0]) + " (this reader knows 0 to 2)");
    const unsigned shift = payload[1];
    const int32_t lo = getI32(payload.data() + 2), hi = getI32(payload.data() + 6);
    if (shift > 31) throw Error(what + ": float integers shifted by " + std::to_string(shift) + " bits (at most 31)");
    // Every integer in [lo, hi] must map back to a float: |M| within 31 - shift bits.
    const int64_t mMax = int64_t(0x7FFFFFFF >> shift);
    if (lo > hi || lo < -1 - mMax || hi > mMax)
        throw Error(what + ": float integers in " + std::to_string(lo) + ".." + std::to_string(hi) + ", beyond what " + std::to_string(31 - shift) +
                    "-bit magnitudes give");
    std::vector<int32_t> ints(out.size());
    decodePlacedBrickValues(payload.subspan(kHeaderBytes), layout, places, BrickOrder::Raster, optionsFor(lo, hi, payload[0]), ints, what);
    for (size_t i = 0; i < ints.size(); ++i) {
        const int32_t v = ints[i];
        out[i] = v < 0 ? 0x80000000u | (uint32_t(-1 - v) << shift) : uint32_t(v) << shift;
    }
}

} // namespace vdbdag::coding
