// The `normals` group (issue 7 part 2), against the octahedral normal codec
// on main (src/attributes/OctahedralNormal.h; Cigolle et al., Dado et al.
// §4.3) at k = 10, 12, 16, 24, 32 bits, with the bound of issue 3: max
// angular error <= 0.95° x 2^((16-k)/2). Cases: the exact axes (with +0 and
// -0 in the other components) decode exactly; the octahedral seam (z = +0,
// z = -0, |z| tiny); every vector of +-0/+-1/+-1/sqrt2 components; a dense
// sphere of directions; zero-length and non-finite inputs, including the
// central-difference gradients of a truncated level set, which vanish in its
// flat regions: no NaN ever, zero length reported (+z), tiny but non-zero
// vectors keep their direction.
// The `--normals K` channel (ONV values stored per voxel) lives on branch
// `attrs`, not on main yet: when it lands, add it to normalEncoders() (one
// entry per k, decoding through the stored channel) and every case below
// runs on it.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include <fmt/core.h>

#include "src/attributes/OctahedralNormal.h"
#include "src/selftest/CaseGroups.h"

namespace vdbdag::selftest {
namespace {

using Vec = std::array<float, 3>;

struct NormalEncoder {
    std::string name;
    unsigned bits;
    double boundDegrees;
    // Encodes and decodes one vector; sets *zeroLength when the input had no direction.
    std::function<Vec(const Vec&, bool* zeroLength)> roundTrip;
};

std::vector<NormalEncoder> normalEncoders() {
    std::vector<NormalEncoder> encoders;
    for (unsigned k : {10u, 12u, 16u, 24u, 32u})
        encoders.push_back({fmt::format("onv{}", k), k, 0.95 * std::pow(2.0, (16.0 - double(k)) / 2.0), [k](const Vec& n, bool* zero) {
                                return attributes::decodeOctahedral(attributes::encodeOctahedral(n, k, zero), k);
                            }});
    return encoders;
}

bool finiteUnit(const Vec& v) {
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) return false;
    const double len = std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
    return std::fabs(len - 1.0) < 1e-5;
}

std::string vecText(const Vec& v) { return fmt::format("({:g},{:g},{:g})", v[0], v[1], v[2]); }

// Every encoder on every direction: finite unit output, not reported as
// zero length, angle <= the encoder's bound. Figures: worst angle per k.
Measurement checkDirections(const std::vector<Vec>& dirs) {
    Checks checks;
    std::string figure;
    double worstRatio = 0;
    for (const NormalEncoder& e : normalEncoders()) {
        double worst = 0;
        for (const Vec& d : dirs) {
            bool zero = false;
            const Vec back = e.roundTrip(d, &zero);
            if (!checks.require(finiteUnit(back), fmt::format("{}: {} decoded to {}", e.name, vecText(d), vecText(back)))) continue;
            checks.require(!zero, fmt::format("{}: {} reported as zero length", e.name, vecText(d)));
            const double angle = attributes::angleDegrees(d, back);
            checks.require(angle <= e.boundDegrees, fmt::format("{}: {} off by {:.4g}° > {:.4g}°", e.name, vecText(d), angle, e.boundDegrees));
            worst = std::max(worst, angle);
        }
        worstRatio = std::max(worstRatio, worst / e.boundDegrees);
        figure += fmt::format("{}{} {:.3g}°/{:.3g}°", figure.empty() ? "" : ", ", e.name, worst, e.boundDegrees);
    }
    return checks.result(fmt::format("worst {:.2f} x bound", worstRatio), fmt::format("{} directions; max angle / bound: {}", dirs.size(), figure));
}

// Central differences of phi = clamp(0.6x + 0.8z - 12.3, -3, 3) on the
// interior of 16^3 points: a truncated (narrow-band) level set of a tilted
// plane, whose gradient is (0.6, 0, 0.8) in the band, something else at the
// band's edges and exactly zero in the flat regions on both sides.
std::vector<Vec> levelSetGradients() {
    auto phi = [](int x, int y, int z) { return std::clamp(0.6f * float(x) + 0.8f * float(z) - 12.3f + 0.0f * float(y), -3.0f, 3.0f); };
    std::vector<Vec> g;
    for (int z = 1; z < 15; ++z)
        for (int y = 1; y < 15; ++y)
            for (int x = 1; x < 15; ++x)
                g.push_back({0.5f * (phi(x + 1, y, z) - phi(x - 1, y, z)), 0.5f * (phi(x, y + 1, z) - phi(x, y - 1, z)),
                             0.5f * (phi(x, y, z + 1) - phi(x, y, z - 1))});
    return g;
}

void addCases(std::vector<SelftestCase>& cases) {
    const std::string kBound = "0.95° x 2^((16-k)/2)";
    cases.push_back({"normals", "axes", "exact", "k = 10..32: the 6 axes with +0/-0 in the other components decode exactly (components 0 or +-1, angle 0)", [] {
                         Checks checks;
                         size_t n = 0, exact = 0;
                         for (const NormalEncoder& e : normalEncoders())
                             for (int axis = 0; axis < 3; ++axis)
                                 for (float s : {1.0f, -1.0f})
                                     for (int zeros = 0; zeros < 4; ++zeros) {
                                         Vec d{zeros & 1 ? -0.0f : 0.0f, zeros & 2 ? -0.0f : 0.0f, 0.0f};
                                         d[2] = d[axis];
                                         d[axis] = s;
                                         if (axis == 2) d[0] = zeros & 1 ? -0.0f : 0.0f;
                                         const Vec back = e.roundTrip(d, nullptr);
                                         ++n;
                                         exact += checks.require(back[0] == d[0] && back[1] == d[1] && back[2] == d[2],
                                                        fmt::format("{}: axis {} decoded to {}", e.name, vecText(d), vecText(back)));
                                     }
                         return checks.result(fmt::format("{}/{} exact", exact, n), fmt::format("{} of {} axis encodings (5 widths x 24) exact", exact, n));
                     }});

    cases.push_back({"normals", "octahedral-seam", "angle <= bound(k)", "k = 10..32: 3600 directions each on z = +0 and z = -0, and at |z| = 1e-7, 1e-30, 1e-45: angle <= " + kBound + ", no NaN", [] {
                         std::vector<Vec> dirs;
                         for (int i = 0; i < 3600; ++i) {
                             const double a = 2 * M_PI * i / 3600.0;
                             const float x = float(std::cos(a)), y = float(std::sin(a));
                             for (float z : {0.0f, -0.0f, 1e-7f, -1e-7f, 1e-30f, -1e-30f, std::numeric_limits<float>::denorm_min(), -std::numeric_limits<float>::denorm_min()})
                                 dirs.push_back({x, y, z});
                         }
                         return checkDirections(dirs);
                     }});

    cases.push_back({"normals", "signed-zeros", "angle <= bound(k)", "k = 10..32: every non-zero vector with components in {+0, -0, +1, -1, +-1/sqrt2}: angle <= " + kBound + ", no NaN", [] {
                         const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, float(M_SQRT1_2), -float(M_SQRT1_2)};
                         std::vector<Vec> dirs;
                         for (float x : values)
                             for (float y : values)
                                 for (float z : values)
                                     if (x != 0 || y != 0 || z != 0) dirs.push_back({x, y, z});
                         return checkDirections(dirs);
                     }});

    cases.push_back({"normals", "sphere", "angle <= bound(k)", "k = 10..32: 50000 Fibonacci-sphere directions: angle <= " + kBound, [] {
                         std::vector<Vec> dirs;
                         const int n = 50000;
                         const double golden = M_PI * (3.0 - std::sqrt(5.0));
                         for (int i = 0; i < n; ++i) {
                             const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z), phi = golden * i;
                             dirs.push_back({float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)});
                         }
                         return checkDirections(dirs);
                     }});

    cases.push_back({"normals", "zero-length-and-flat-gradients", "no NaN, zero reported",
                     "k = 10..32: zero (+-0), NaN and Inf vectors and the zero gradients of a truncated level set's flat regions decode to "
                     "a finite unit vector, reported as zero length; tiny non-zero vectors (1e-45..1e-30) keep their direction within " + kBound,
                     [] {
                         Checks checks;
                         const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
                         std::vector<Vec> degenerate{{0, 0, 0}, {-0.0f, -0.0f, -0.0f}, {0, -0.0f, 0}, {nan, 0, 0}, {0, nan, 1}, {inf, 0, 0}, {inf, -inf, 0}, {nan, nan, nan}};
                         size_t flat = 0, band = 0;
                         std::vector<Vec> tiny{{std::numeric_limits<float>::denorm_min(), 0, 0}, {0, -std::numeric_limits<float>::denorm_min(), 0},
                                               {1e-30f, -1e-30f, 0}, {0, 0, -1e-38f}};
                         for (const Vec& g : levelSetGradients()) {
                             if (g[0] == 0 && g[1] == 0 && g[2] == 0) degenerate.push_back(g), ++flat;
                             else tiny.push_back(g), ++band;
                         }
                         for (const NormalEncoder& e : normalEncoders()) {
                             for (const Vec& d : degenerate) {
                                 bool zero = false;
                                 const Vec back = e.roundTrip(d, &zero);
                                 checks.require(finiteUnit(back), fmt::format("{}: {} decoded to {}", e.name, vecText(d), vecText(back)));
                                 checks.require(zero, fmt::format("{}: {} not reported as zero length", e.name, vecText(d)));
                             }
                             for (const Vec& d : tiny) {
                                 bool zero = true;
                                 const Vec back = e.roundTrip(d, &zero);
                                 checks.require(finiteUnit(back) && !zero, fmt::format("{}: {} decoded to {} (zero length: {})", e.name, vecText(d), vecText(back), zero));
                                 checks.require(attributes::angleDegrees(d, back) <= e.boundDegrees, fmt::format("{}: {} lost its direction", e.name, vecText(d)));
                             }
                         }
                         return checks.result(fmt::format("{} degenerate ok", degenerate.size()), fmt::format("{} degenerate vectors ({} flat-region gradients) -> finite +z, reported; {} non-zero ({} in the band) "
                                                          "within the bound; 5 widths",
                                                          degenerate.size(), flat, tiny.size(), band));
                     }});
}

} // namespace

void addNormalCases(std::vector<SelftestCase>& cases) { addCases(cases); }

} // namespace vdbdag::selftest
