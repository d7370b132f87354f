// See CieLab.h. Constants: sRGB primaries and D65 white (X 0.95047, Y 1,
// Z 1.08883); CIE's exact epsilon 216/24389 and kappa 24389/27.
#include "src/attributes/CieLab.h"

#include <cmath>

namespace vdbdag::attributes {
namespace {

constexpr double kWhite[3] = {0.95047, 1.0, 1.08883};
constexpr double kEpsilon = 216.0 / 24389.0, kKappa = 24389.0 / 27.0;

double toLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }
double toGamma(double c) { return c <= 0.0031308 ? c * 12.92 : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055; }
double f(double t) { return t > kEpsilon ? std::cbrt(t) : (kKappa * t + 16.0) / 116.0; }
double fInverse(double t) { return t * t * t > kEpsilon ? t * t * t : (116.0 * t - 16.0) / kKappa; }

} // namespace

Lab srgbToLab(const Rgb& rgb) {
    const double r = toLinear(rgb[0]), g = toLinear(rgb[1]), b = toLinear(rgb[2]);
    const double x = 0.4124564 * r + 0.3575761 * g + 0.1804375 * b;
    const double y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b;
    const double z = 0.0193339 * r + 0.1191920 * g + 0.9503041 * b;
    const double fx = f(x / kWhite[0]), fy = f(y / kWhite[1]), fz = f(z / kWhite[2]);
    return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

Rgb labToSrgb(const Lab& lab) {
    const double fy = (lab[0] + 16.0) / 116.0, fx = fy + lab[1] / 500.0, fz = fy - lab[2] / 200.0;
    const double x = fInverse(fx) * kWhite[0];
    const double y = (lab[0] > kKappa * kEpsilon ? fy * fy * fy : lab[0] / kKappa) * kWhite[1];
    const double z = fInverse(fz) * kWhite[2];
    const double r = 3.2404542 * x - 1.5371385 * y - 0.4985314 * z;
    const double g = -0.9692660 * x + 1.8760108 * y + 0.0415560 * z;
    const double b = 0.0556434 * x - 0.2040259 * y + 1.0572252 * z;
    return {toGamma(r), toGamma(g), toGamma(b)};
}

double deltaE94(const Lab& reference, const Lab& sample) {
    constexpr double kL = 1.0, K1 = 0.045, K2 = 0.015;
    const double dL = reference[0] - sample[0];
    const double c1 = std::hypot(reference[1], reference[2]), c2 = std::hypot(sample[1], sample[2]);
    const double dC = c1 - c2;
    const double da = reference[1] - sample[1], db = reference[2] - sample[2];
    const double dH2 = std::max(0.0, da * da + db * db - dC * dC);
    const double sL = 1.0, sC = 1.0 + K1 * c1, sH = 1.0 + K2 * c1;
    const double tL = dL / (kL * sL), tC = dC / sC;
    return std::sqrt(tL * tL + tC * tC + dH2 / (sH * sH));
}

} // namespace vdbdag::attributes
