// The `colours` group (issue 7 part 2), against the CIELAB codec on main
// (src/attributes/CieLab.h) and the lossless vec3 value channel:
//  - black, white and the saturated primaries and secondaries: CIELAB
//    within 0.01 of published values (Lindbloom's sRGB/D65 calculator), and
//    back to sRGB within 1e-5 (the published matrices are rounded to 7
//    digits, so they are inverse only to about 1e-7 per coefficient);
//  - a channel of identical colours, lossless: bit-exact, a handful of bytes;
//  - every k-bit colour quantiser in colourQuantisers(): all-identical
//    input gives one colour; more unique colours than 2^k give at most 2^k;
//    a smooth gradient bands into at most 2^k steps; every ΔE*94 within the
//    quantiser's closed-form bound, no NaN.
// The CIELAB clustering of `--colour-bits K` (Dado et al. §4.3) lives on
// branch `attrs`, not on main yet: until it lands, the quantiser under test
// is a uniform k-bit grid over L*a*b* (cell centres), whose worst ΔE*94 is
// bounded in closed form: ΔE*94 <= ΔE*76 (its weights S_C, S_H are >= 1)
// <= half the cell diagonal. Adding the clustering is one entry in
// colourQuantisers(), with its own bound.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <set>

#include <fmt/core.h>

#include "src/attributes/CieLab.h"
#include "src/selftest/CaseGroups.h"
#include "src/selftest/FileRoundTrip.h"
#include "src/selftest/SyntheticGrid.h"

namespace vdbdag::selftest {
namespace {

using attributes::Lab;
using attributes::Rgb;

// A k-bit colour quantiser under test: input sRGB colours in [0,1], output
// sRGB colours (not clamped); at most 2^bits distinct outputs allowed, every
// ΔE*94 (input as reference) at most maxDeltaE94.
struct ColourQuantiser {
    std::string name;
    unsigned bits;
    double maxDeltaE94;
    std::string boundReason;
    std::function<std::vector<Rgb>(const std::vector<Rgb>&)> quantise;
};

// Uniform grid over L* in [0, 100], a* and b* in [-128, 128]: bitsL, bitsA,
// bitsB bits; each colour goes to its cell's centre.
ColourQuantiser labGridQuantiser(unsigned k) {
    const unsigned bl = (k + 2) / 3, ba = (k - bl + 1) / 2, bb = k - bl - ba;
    const double sl = 100.0 / double(1u << bl), sa = 256.0 / double(1u << ba), sb = 256.0 / double(1u << bb);
    // + the conversions' rounding: the published sRGB <-> XYZ matrices are
    // inverse only to 7 digits, so Lab -> sRGB -> Lab moves a colour by up to
    // 6.2e-5 ΔE*94 over the whole L*a*b* box (measured on a 0.5/1/1 lattice).
    const double bound = 0.5 * std::sqrt(sl * sl + sa * sa + sb * sb) + 1e-3;
    ColourQuantiser q;
    q.name = fmt::format("lab-grid-k{}", k);
    q.bits = k;
    q.maxDeltaE94 = bound;
    q.boundReason = fmt::format("half the diagonal of a {}x{}x{} cell; quantiser: a uniform k-bit L*a*b* grid, standing in until the "
                                "--colour-bits clustering (branch attrs) is on main",
                                sl, sa, sb);
    q.quantise = [=](const std::vector<Rgb>& in) {
        std::vector<Rgb> out;
        out.reserve(in.size());
        auto cell = [](double v, double lo, double step, unsigned b) {
            const double i = std::clamp(std::floor((v - lo) / step), 0.0, double((1u << b) - 1));
            return lo + (i + 0.5) * step;
        };
        for (const Rgb& c : in) {
            const Lab lab = attributes::srgbToLab(c);
            out.push_back(attributes::labToSrgb({cell(lab[0], 0.0, sl, bl), cell(lab[1], -128.0, sa, ba), cell(lab[2], -128.0, sb, bb)}));
        }
        return out;
    };
    return q;
}

// The quantisers every `colours/...-k*` case runs. When `--colour-bits K`
// (CIELAB clustering, branch attrs) is on main, add it here, k = 10, 12, 14,
// with its own bound.
std::vector<ColourQuantiser> colourQuantisers() {
    std::vector<ColourQuantiser> q;
    for (unsigned k : {10u, 12u, 14u}) q.push_back(labGridQuantiser(k));
    return q;
}

struct QuantiserFigures {
    Checks checks;
    size_t distinctIn = 0, distinctOut = 0;
    double maxDeltaE = 0, meanDeltaE = 0, maxRgbError = 0, maxStepDeltaE = 0;
};

// Runs `q` on `colours` and checks: finite outputs, <= 2^bits distinct
// outputs, ΔE*94 <= bound for every colour.
QuantiserFigures runQuantiser(const ColourQuantiser& q, const std::vector<Rgb>& colours) {
    QuantiserFigures f;
    const std::vector<Rgb> out = q.quantise(colours);
    if (!f.checks.require(out.size() == colours.size(), "the quantiser returned the wrong number of colours")) return f;
    std::set<Rgb> in, outSet;
    double sum = 0;
    for (size_t i = 0; i < colours.size(); ++i) {
        in.insert(colours[i]);
        outSet.insert(out[i]);
        const Rgb& c = out[i];
        if (!f.checks.require(std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]),
                              fmt::format("colour {} became non-finite ({}, {}, {})", i, c[0], c[1], c[2])))
            continue;
        const Lab ref = attributes::srgbToLab(colours[i]), got = attributes::srgbToLab(c);
        const double de = attributes::deltaE94(ref, got);
        f.checks.require(std::isfinite(de) && de <= q.maxDeltaE94,
                         fmt::format("colour ({:.4f},{:.4f},{:.4f}): ΔE94 {:.4f} > {:.4f}", colours[i][0], colours[i][1], colours[i][2], de, q.maxDeltaE94));
        f.maxDeltaE = std::max(f.maxDeltaE, de);
        sum += de;
        for (int a = 0; a < 3; ++a) f.maxRgbError = std::max(f.maxRgbError, std::fabs(std::clamp(c[a], 0.0, 1.0) - colours[i][a]));
        if (i > 0) f.maxStepDeltaE = std::max(f.maxStepDeltaE, attributes::deltaE94(attributes::srgbToLab(out[i - 1]), got));
    }
    f.meanDeltaE = colours.empty() ? 0 : sum / double(colours.size());
    f.distinctIn = in.size();
    f.distinctOut = outSet.size();
    f.checks.require(f.distinctOut <= (size_t(1) << q.bits), fmt::format("{} distinct colours out, more than 2^{}", f.distinctOut, q.bits));
    return f;
}

const std::vector<std::pair<const char*, Rgb>>& primaries() {
    static const std::vector<std::pair<const char*, Rgb>> p{{"black", {0, 0, 0}}, {"white", {1, 1, 1}},   {"red", {1, 0, 0}},
                                                             {"green", {0, 1, 0}}, {"blue", {0, 0, 1}},    {"cyan", {0, 1, 1}},
                                                             {"magenta", {1, 0, 1}}, {"yellow", {1, 1, 0}}};
    return p;
}

void addCases(std::vector<SelftestCase>& cases) {
    static constexpr double kLabTolerance = 0.01, kRgbTolerance = 1e-5;
    cases.push_back({"colours", "primaries-cielab", fmt::format("|ΔLab| <= {}", kLabTolerance),
                     fmt::format("black, white, R, G, B, C, M, Y: L*a*b* within {} of published values, back to sRGB within {}, no NaN",
                                 kLabTolerance, kRgbTolerance),
                     [] {
                         // Lindbloom's calculator, sRGB, D65 reference white.
                         const Lab published[] = {{0, 0, 0},
                                                  {100, 0, 0},
                                                  {53.2408, 80.0925, 67.2032},
                                                  {87.7347, -86.1827, 83.1793},
                                                  {32.2970, 79.1875, -107.8602},
                                                  {91.1132, -48.0875, -14.1312},
                                                  {60.3242, 98.2343, -60.8249},
                                                  {97.1393, -21.5537, 94.4780}};
                         Checks checks;
                         double maxLab = 0, maxRgb = 0;
                         for (size_t i = 0; i < primaries().size(); ++i) {
                             const auto& [name, rgb] = primaries()[i];
                             const Lab lab = attributes::srgbToLab(rgb);
                             const Rgb back = attributes::labToSrgb(lab);
                             for (int a = 0; a < 3; ++a) {
                                 const double dl = std::fabs(lab[a] - published[i][a]), dr = std::fabs(back[a] - rgb[a]);
                                 checks.require(std::isfinite(lab[a]) && dl <= kLabTolerance,
                                                fmt::format("{}: L*a*b*[{}] = {:.4f}, published {:.4f}", name, a, lab[a], published[i][a]));
                                 checks.require(std::isfinite(back[a]) && dr <= kRgbTolerance, fmt::format("{}: sRGB[{}] came back as {:.8f}", name, a, back[a]));
                                 maxLab = std::max(maxLab, dl);
                                 maxRgb = std::max(maxRgb, dr);
                             }
                         }
                         return checks.result(fmt::format("|ΔLab| {:.2g}", maxLab), fmt::format("max |ΔL*a*b*| {:.2g} against published, max sRGB round-trip error {:.2g}", maxLab, maxRgb));
                     }});

    static constexpr uint64_t kChannelBound = 64;
    cases.push_back({"colours", "identical-lossless", fmt::format("channel <= {} B", kChannelBound),
                     fmt::format("4096 identical vec3s colours (a Cd grid), lossless: bit-exact, value channel <= {} bytes", kChannelBound),
                     [] {
                         SyntheticGrid grid;
                         grid.type = ValueType::Vec3S;
                         const float c[3] = {0.8f, 0.25f, 0.1f};
                         for (int i = 0; i < 4096; ++i) grid.addVoxel(i % 16, i / 16 % 16, i / 256, c);
                         const GridRecord record = toRecord(grid, "Cd");
                         const FileRoundTrip rt = roundTripThroughFile(record);
                         Checks checks;
                         const std::string diff = firstDifference(flatten(record), flatten(rt.decoded));
                         checks.require(diff.empty(), diff);
                         checks.require(rt.channelBytes() <= kChannelBound, fmt::format("value channel {} bytes", rt.channelBytes()));
                         return checks.result(fmt::format("{} B", rt.channelBytes()), fmt::format("value channel {} bytes for 4096 entries, file {} bytes", rt.channelBytes(), rt.fileBytes));
                     }});

    for (const ColourQuantiser& q : colourQuantisers()) {
        const std::string limit = fmt::format("ΔE94 <= {:.2f}", q.maxDeltaE94);
        const std::string bound = fmt::format("ΔE*94 <= {:.3f} ({}), <= 2^{} distinct colours out, no NaN", q.maxDeltaE94, q.boundReason, q.bits);
        cases.push_back({"colours", "identical-" + q.name, "1 colour, " + limit, "4096 identical colours: one colour out; " + bound, [q] {
                             QuantiserFigures f = runQuantiser(q, std::vector<Rgb>(4096, Rgb{0.8, 0.25, 0.1}));
                             f.checks.require(f.distinctOut == 1, fmt::format("{} distinct colours out of one", f.distinctOut));
                             return f.checks.result(fmt::format("{} colour, ΔE94 {:.2f}", f.distinctOut, f.maxDeltaE),
                                                    fmt::format("{} colour out, ΔE*94 {:.3f}", f.distinctOut, f.maxDeltaE));
                         }});
        cases.push_back({"colours", "many-unique-" + q.name, fmt::format("<= 2^{} colours, {}", q.bits, limit),
                         fmt::format("65536 distinct colours (random, the primaries, black, white) > 2^{}: {}", q.bits, bound), [q] {
                             std::mt19937_64 rng(7);
                             std::uniform_real_distribution<double> u(0.0, 1.0);
                             std::vector<Rgb> colours;
                             for (const auto& p : primaries()) colours.push_back(p.second);
                             std::set<Rgb> seen(colours.begin(), colours.end());
                             while (colours.size() < 65536) {
                                 const Rgb c{u(rng), u(rng), u(rng)};
                                 if (seen.insert(c).second) colours.push_back(c);
                             }
                             QuantiserFigures f = runQuantiser(q, colours);
                             return f.checks.result(fmt::format("{} colours, ΔE94 {:.2f}", f.distinctOut, f.maxDeltaE),
                                                    fmt::format("{} -> {} colours; ΔE*94 max {:.3f} mean {:.3f}; max |ΔRGB| {:.4f} (clamped)", f.distinctIn,
                                                                f.distinctOut, f.maxDeltaE, f.meanDeltaE, f.maxRgbError));
                         }});
        cases.push_back({"colours", "gradient-" + q.name, limit, "a 4096-step gradient dark blue -> orange (banding): " + bound, [q] {
                             std::vector<Rgb> colours;
                             for (int i = 0; i < 4096; ++i) {
                                 const double t = double(i) / 4095.0;
                                 colours.push_back({0.05 + 0.9 * t, 0.1 + 0.45 * t, 0.4 - 0.35 * t});
                             }
                             QuantiserFigures f = runQuantiser(q, colours);
                             return f.checks.result(fmt::format("ΔE94 {:.2f}, {} bands", f.maxDeltaE, f.distinctOut),
                                                    fmt::format("{} bands; ΔE*94 max {:.3f} mean {:.3f}; largest step between bands ΔE*94 {:.3f}",
                                                                f.distinctOut, f.maxDeltaE, f.meanDeltaE, f.maxStepDeltaE));
                         }});
    }
}

} // namespace

void addColourCases(std::vector<SelftestCase>& cases) { addCases(cases); }

} // namespace vdbdag::selftest
