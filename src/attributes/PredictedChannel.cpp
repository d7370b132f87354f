// See PredictedChannel.h.
#include "src/attributes/PredictedChannel.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <type_traits>

#include "src/util/Error.h"

namespace vdbdag::attributes {
namespace {

constexpr uint8_t kBrickMed = 1;

template <typename U>
inline U med(U ua, U ub, U uc) {
    using S = std::make_signed_t<U>;
    const S a = S(ua), b = S(ub), c = S(uc);
    if (c >= std::max(a, b)) return U(std::min(a, b));
    if (c <= std::min(a, b)) return U(std::max(a, b));
    return U(ua + ub - uc);  // wraps, but the true value lies between a and b
}

// Walks every entry in attribute order with its prediction: fn(entryIndex,
// prediction) must return the entry's actual value (read or reconstructed).
template <typename U, typename Fn>
void walk(std::span<const uint64_t> layout, uint64_t entries, Fn&& fn) {
    U brick[64];
    U last = 0;
    uint64_t e = 0;
    for (const uint64_t mask : layout) {
        if (mask == 0) {
            if (e >= entries) throw Error("layout holds more entries than the channel");
            last = fn(e++, last);
            continue;
        }
        if (e + uint64_t(std::popcount(mask)) > entries) throw Error("layout holds more entries than the channel");
        for (uint64_t bits = mask; bits; bits &= bits - 1) {
            const unsigned i = unsigned(std::countr_zero(bits));
            const unsigned x = i & 3u, y = (i >> 2) & 3u, z = i >> 4;
            auto has = [&](unsigned j) { return (mask >> j) & 1u; };
            const bool hx = x && has(i - 1), hy = y && has(i - 4), hz = z && has(i - 16);
            U p;
            if (hx && hy && has(i - 5)) p = med<U>(brick[i - 1], brick[i - 4], brick[i - 5]);
            else if (hx && hz && has(i - 17)) p = med<U>(brick[i - 1], brick[i - 16], brick[i - 17]);
            else if (hy && hz && has(i - 20)) p = med<U>(brick[i - 4], brick[i - 16], brick[i - 20]);
            else if (hx) p = brick[i - 1];
            else if (hy) p = brick[i - 4];
            else if (hz) p = brick[i - 16];
            else p = last;
            brick[i] = fn(e++, p);
            last = brick[i];
        }
    }
    if (e != entries) throw Error("layout holds " + std::to_string(e) + " entries, the channel " + std::to_string(entries));
}

template <typename U>
inline U zigzag(U r) {
    return U(r << 1) ^ U(std::make_signed_t<U>(r) >> (sizeof(U) * 8 - 1));
}

// Two walks (the first finds the residual width, the second writes the
// planes), so memory holds the output only, not a residual array as well.
template <typename U>
std::vector<uint8_t> encodeTyped(std::span<const uint8_t> values, std::span<const uint64_t> layout) {
    const uint64_t n = values.size() / sizeof(U);
    auto valueAt = [&](uint64_t e) {
        U v;
        std::memcpy(&v, values.data() + e * sizeof(U), sizeof(U));
        return v;
    };
    U widest = 0;
    walk<U>(layout, n, [&](uint64_t e, U p) {
        const U v = valueAt(e);
        widest |= zigzag<U>(U(v - p));
        return v;
    });
    const uint64_t wide = uint64_t(widest);
    const uint8_t width = (wide >> 32) ? 8 : (wide >> 16) ? 4 : (wide >> 8) ? 2 : 1;
    std::vector<uint8_t> out(3 + 8 + n * width);
    out[0] = kBrickMed;
    out[1] = uint8_t(sizeof(U));
    out[2] = width;
    std::memcpy(out.data() + 3, &n, 8);
    uint8_t* planes = out.data() + 11;
    walk<U>(layout, n, [&](uint64_t e, U p) {
        const U v = valueAt(e);
        const U z = zigzag<U>(U(v - p));
        for (unsigned plane = 0; plane < width; ++plane) planes[plane * n + e] = uint8_t(z >> (8 * plane));
        return v;
    });
    return out;
}

template <typename U>
std::vector<uint8_t> decodeTyped(std::span<const uint8_t> payload, std::span<const uint64_t> layout, const std::string& what) {
    if (payload.size() < 11) throw Error(what + ": predicted channel header truncated");
    const uint8_t width = payload[2];
    uint64_t n;
    std::memcpy(&n, payload.data() + 3, 8);
    if (width != 1 && width != 2 && width != 4 && width != 8) throw Error(what + ": predicted channel has residual width " + std::to_string(width));
    if (width > sizeof(U)) throw Error(what + ": predicted channel residuals wider than its values");
    if (n > (payload.size() - 11) / width || 11 + n * width != payload.size())
        throw Error(what + ": predicted channel holds " + std::to_string(payload.size() - 11) + " residual bytes, expected " + std::to_string(n) + " x " +
                    std::to_string(width));
    std::vector<uint8_t> out(n * sizeof(U));
    const uint8_t* planes = payload.data() + 11;
    try {
        walk<U>(layout, n, [&](uint64_t e, U p) {
            U z = 0;
            for (unsigned plane = 0; plane < width; ++plane) z |= U(planes[plane * n + e]) << (8 * plane);
            const U r = U(z >> 1) ^ U(U(0) - (z & 1));
            const U v = U(p + r);
            std::memcpy(out.data() + e * sizeof(U), &v, sizeof(U));
            return v;
        });
    } catch (const Error& e) {
        throw Error(what + ": " + e.what());
    }
    return out;
}

} // namespace

std::vector<uint8_t> encodePredicted(std::span<const uint8_t> values, uint32_t valueSize, std::span<const uint64_t> layout) {
    if (valueSize == 4) return encodeTyped<uint32_t>(values, layout);
    if (valueSize == 8) return encodeTyped<uint64_t>(values, layout);
    throw Error("internal error: predicted channels hold 4- or 8-byte integers");
}

std::vector<uint8_t> decodePredicted(std::span<const uint8_t> payload, uint32_t valueSize, std::span<const uint64_t> layout,
                                     const std::string& what) {
    if (payload.size() < 3) throw Error(what + ": predicted channel header truncated");
    if (payload[0] != kBrickMed) throw Error(what + ": unknown predictor " + std::to_string(payload[0]));
    if (payload[1] != valueSize) throw Error(what + ": predicted channel holds " + std::to_string(payload[1]) + "-byte values, expected " + std::to_string(valueSize));
    if (valueSize == 4) return decodeTyped<uint32_t>(payload, layout, what);
    if (valueSize == 8) return decodeTyped<uint64_t>(payload, layout, what);
    throw Error(what + ": predicted channels hold 4- or 8-byte integers");
}

} // namespace vdbdag::attributes
