// CIELAB conversions and the CIE94 colour difference used to quantise and
// to report colour error (Dado et al. §4.3, Table 2): sRGB (IEC 61966-2-1
// transfer curve) <-> linear RGB <-> XYZ (D65) <-> L*a*b*, and ΔE*94 with
// the graphic-arts constants kL = 1, K1 = 0.045, K2 = 0.015.
#pragma once
#include <array>

namespace vdbdag::attributes {

using Lab = std::array<double, 3>;
using Rgb = std::array<double, 3>;  // sRGB components in [0, 1]

Lab srgbToLab(const Rgb& rgb);
Rgb labToSrgb(const Lab& lab);  // not clamped: out-of-gamut colours come back out of [0, 1]

// ΔE*94 of `sample` against `reference` (not symmetric: the weights use the
// reference's chroma, as CIE94 defines).
double deltaE94(const Lab& reference, const Lab& sample);

} // namespace vdbdag::attributes
