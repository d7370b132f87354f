// See OctahedralNormal.h.
#include "src/attributes/OctahedralNormal.h"

#include <vdbdag/normal_access.h>

#include <algorithm>
#include <cmath>

namespace vdbdag::attributes {
namespace {

double signNotZero(double v) { return v >= 0.0 ? 1.0 : -1.0; }  // -0.0 counts as positive: no NaN, no zero

// Unit vector -> point of the [-1,1]^2 square.
std::array<double, 2> fold(double x, double y, double z) {
    const double l1 = std::fabs(x) + std::fabs(y) + std::fabs(z);
    double u = x / l1, v = y / l1;
    if (z < 0.0) {
        const double fu = (1.0 - std::fabs(v)) * signNotZero(u), fv = (1.0 - std::fabs(u)) * signNotZero(v);
        u = fu;
        v = fv;
    }
    return {u, v};
}

} // namespace

OctahedralCode encodeOctahedral(const std::array<float, 3>& n, unsigned k, bool* zeroLength) {
    const unsigned half = k / 2;
    const double scale = double((uint64_t(1) << (half - 1)) - 1);
    double x = n[0], y = n[1], z = n[2];
    const double len = std::sqrt(x * x + y * y + z * z);
    const bool degenerate = !(len > 0.0) || !std::isfinite(len);
    if (zeroLength) *zeroLength = degenerate;
    if (degenerate) { x = 0; y = 0; z = 1; } else { x /= len; y /= len; z /= len; }
    const auto [u, v] = fold(x, y, z);
    // Best of the four lattice neighbours by angular error.
    double best = -2.0;
    int64_t bu = 0, bv = 0;
    for (int du = 0; du < 2; ++du)
        for (int dv = 0; dv < 2; ++dv) {
            const int64_t qu = std::clamp<int64_t>(int64_t(std::floor(u * scale)) + du, -int64_t(scale), int64_t(scale));
            const int64_t qv = std::clamp<int64_t>(int64_t(std::floor(v * scale)) + dv, -int64_t(scale), int64_t(scale));
            std::array<double, 3> d{};
            access::onvUnfold(double(qu) / scale, double(qv) / scale, d[0], d[1], d[2]);
            const double cosine = d[0] * x + d[1] * y + d[2] * z;
            if (cosine > best) { best = cosine; bu = qu; bv = qv; }
        }
    const uint32_t mask = half >= 32 ? 0xFFFFFFFFu : (uint32_t(1) << half) - 1;
    return {(uint32_t(bu) & mask) | ((uint32_t(bv) & mask) << half)};
}

std::array<float, 3> decodeOctahedral(OctahedralCode code, unsigned k) {
    std::array<float, 3> n{};
    access::onvDecode(code.bits, k, n[0], n[1], n[2]);
    return n;
}

double angleDegrees(const std::array<float, 3>& a, const std::array<float, 3>& b) {
    const double la = std::sqrt(double(a[0]) * a[0] + double(a[1]) * a[1] + double(a[2]) * a[2]);
    const double lb = std::sqrt(double(b[0]) * b[0] + double(b[1]) * b[1] + double(b[2]) * b[2]);
    if (!(la > 0) || !(lb > 0)) return 0.0;
    // atan2 of |cross| and dot: accurate for tiny angles, unlike acos.
    const double cx = double(a[1]) * b[2] - double(a[2]) * b[1], cy = double(a[2]) * b[0] - double(a[0]) * b[2], cz = double(a[0]) * b[1] - double(a[1]) * b[0];
    const double dot = double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
    return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot) * 180.0 / M_PI;
}

} // namespace vdbdag::attributes
