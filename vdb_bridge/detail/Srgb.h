// Linear light to an 8-bit sRGB code (IEC 61966-2-1), as the PNG frames
// store it; NaN and values outside [0, 1] are clamped. Shared by the PNG
// writer (vdb_bridge/PngFile) and the image module's other 8-bit formats.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace vdbdag::bridge::detail {

inline float linearToSrgb(float c) {
    c = std::clamp(std::isfinite(c) ? c : 0.f, 0.f, 1.f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1 / 2.4f) - 0.055f;
}

inline uint8_t srgbByte(float linear) { return uint8_t(std::lround(linearToSrgb(linear) * 255.f)); }

} // namespace vdbdag::bridge::detail
