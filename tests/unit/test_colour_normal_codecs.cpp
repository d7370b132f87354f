// Closed-form checks of the attribute codecs: octahedral normals against the
// angular bound 0.95 deg * 2^((16-k)/2) over a dense sphere of directions,
// the axes, the z = 0 seam and +-0 components (no NaN); CIELAB against
// published reference values; ΔE*94 against a published pair and its
// symmetric cases. A normal channel quantised piece by piece against each
// entry's own octahedral code and a plain sum of its angular errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "src/attributes/CieLab.h"
#include "src/attributes/NormalChannel.h"
#include "src/attributes/OctahedralNormal.h"

using namespace vdbdag::attributes;

namespace {

std::vector<std::array<float, 3>> testDirections() {
    std::vector<std::array<float, 3>> dirs;
    const int n = 200000;  // Fibonacci sphere
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z), phi = golden * i;
        dirs.push_back({float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)});
    }
    for (float s : {1.0f, -1.0f}) {  // the axes, with signed zeros
        dirs.push_back({s, 0.0f, 0.0f}); dirs.push_back({0.0f, s, 0.0f}); dirs.push_back({0.0f, 0.0f, s});
        dirs.push_back({s, -0.0f, -0.0f}); dirs.push_back({-0.0f, s, -0.0f}); dirs.push_back({-0.0f, -0.0f, s});
    }
    for (int i = 0; i < 3600; ++i) {  // the z = 0 seam, with +0 and -0
        const double a = 2 * M_PI * i / 3600.0;
        dirs.push_back({float(std::cos(a)), float(std::sin(a)), 0.0f});
        dirs.push_back({float(std::cos(a)), float(std::sin(a)), -0.0f});
    }
    return dirs;
}

} // namespace

TEST(OctahedralNormal, AngularErrorWithinTheBoundForEveryWidth) {
    const auto dirs = testDirections();
    for (unsigned k : {10u, 12u, 16u, 24u, 32u}) {
        const double bound = 0.95 * std::pow(2.0, (16.0 - double(k)) / 2.0);
        double worst = 0;
        for (const auto& d : dirs) {
            const auto back = decodeOctahedral(encodeOctahedral(d, k), k);
            ASSERT_TRUE(std::isfinite(back[0]) && std::isfinite(back[1]) && std::isfinite(back[2]));
            worst = std::max(worst, angleDegrees(d, back));
        }
        EXPECT_LE(worst, bound) << k << "-bit ONV";
        RecordProperty("max_angle_deg_k" + std::to_string(k), std::to_string(worst));
    }
    // The axes come back exactly (to float precision).
    for (unsigned k : {10u, 16u, 32u})
        for (const std::array<float, 3>& axis : {std::array<float, 3>{1, 0, 0}, {0, -1, 0}, {0, 0, -1}, {0, 0, 1}})
            EXPECT_LT(angleDegrees(axis, decodeOctahedral(encodeOctahedral(axis, k), k)), 1e-3) << k;
}

TEST(OctahedralNormal, ZeroLengthInputIsReportedAndEncodesPlusZ) {
    bool zero = false;
    const auto back = decodeOctahedral(encodeOctahedral({0.0f, -0.0f, 0.0f}, 16, &zero), 16);
    EXPECT_TRUE(zero);
    EXPECT_LT(angleDegrees(back, {0, 0, 1}), 1e-3);
    encodeOctahedral({1e-30f, 0, 0}, 16, &zero);
    EXPECT_FALSE(zero);
    const auto nanIn = decodeOctahedral(encodeOctahedral({NAN, 0, 0}, 16, &zero), 16);
    EXPECT_TRUE(zero);
    EXPECT_TRUE(std::isfinite(nanIn[0]));
}

// NormalQuantizer (the cube encoder's streamed normals): pieces of any size,
// quantised in any order and added in attribute order, give the channel
// whose codes are each entry's encodeOctahedral, whose zero-length count is
// that of the zero and non-finite entries, and whose mean and max are the
// plain sum and max of the other entries' errors; encodeNormals the same.
TEST(NormalQuantizer, PiecesInAnyOrderGiveEachEntrysCodeAndThePlainStatistics) {
    std::mt19937 rng(5);
    std::normal_distribution<float> gauss;
    std::vector<std::array<float, 3>> normals(50000);
    for (size_t i = 0; i < normals.size(); ++i) {
        normals[i] = {gauss(rng), gauss(rng), gauss(rng)};
        if (i % 97 == 0) normals[i] = {0.0f, -0.0f, 0.0f};
        if (i % 211 == 0) normals[i][1] = std::numeric_limits<float>::quiet_NaN();
    }
    const unsigned bits = 16;
    uint64_t zero = 0;
    double sum = 0, worst = 0;
    std::vector<uint32_t> codes;
    for (const auto& n : normals) {
        bool z = false;
        const OctahedralCode c = encodeOctahedral(n, bits, &z);
        codes.push_back(c.bits);
        if (z) {
            ++zero;
            continue;
        }
        const double a = angleDegrees(decodeOctahedral(c, bits), n);
        sum += a;
        worst = std::max(worst, a);
    }
    auto check = [&](const NormalChannel& channel) {
        ASSERT_EQ(channel.entryCount(), normals.size());
        for (size_t i = 0; i < normals.size(); ++i) ASSERT_EQ(channel.code(i), codes[i]) << i;
        EXPECT_EQ(channel.report.zeroLength, zero);
        EXPECT_EQ(channel.report.meanAngleDegrees, sum / double(normals.size() - zero));
        EXPECT_EQ(channel.report.maxAngleDegrees, worst);
        EXPECT_EQ(channel.report.oneSided, 7u);
    };
    check(encodeNormals(normals, bits, NormalReport::Source::Gradient, 7));
    // Pieces of 1 to 5000 entries, quantised last first.
    std::vector<std::vector<uint8_t>> pieces;
    for (size_t at = 0; at < normals.size();) {
        const size_t n = std::min<size_t>(normals.size() - at, 1 + rng() % 5000);
        pieces.emplace_back(n * 12);
        std::memcpy(pieces.back().data(), &normals[at], n * 12);
        at += n;
    }
    NormalQuantizer quantizer(bits);
    for (size_t k = pieces.size(); k-- > 0;) quantizer.quantise(pieces[k]);
    for (const auto& piece : pieces) quantizer.add(piece);
    check(quantizer.finish(NormalReport::Source::Gradient, 7));
}

TEST(CieLab, PublishedReferenceValues) {
    struct Case { Rgb rgb; Lab lab; };
    // sRGB (D65) -> CIELAB, as tabulated by Bruce Lindbloom's calculator.
    const Case cases[] = {{{1, 1, 1}, {100.0, 0.0, 0.0}},      {{0, 0, 0}, {0.0, 0.0, 0.0}},
                          {{1, 0, 0}, {53.2408, 80.0925, 67.2032}}, {{0, 1, 0}, {87.7347, -86.1827, 83.1793}},
                          {{0, 0, 1}, {32.2970, 79.1875, -107.8602}}, {{0.5, 0.5, 0.5}, {53.3889, 0.0, 0.0}}};
    for (const Case& c : cases) {
        const Lab lab = srgbToLab(c.rgb);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(lab[i], c.lab[i], 0.01) << "rgb " << c.rgb[0] << "," << c.rgb[1] << "," << c.rgb[2];
        const Rgb back = labToSrgb(lab);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], c.rgb[i], 1e-5);  // the published matrices are rounded to 7 digits
    }
}

TEST(CieLab, DeltaE94PublishedPairAndSymmetricCases) {
    // Sharma, Wu & Dalal's first test pair; ΔE*94 (graphic arts) = 1.3950.
    EXPECT_NEAR(deltaE94({50.0, 2.6772, -79.7751}, {50.0, 0.0, -82.7485}), 1.3950, 5e-4);
    // Pure lightness differences and equal-chroma pairs are symmetric.
    EXPECT_DOUBLE_EQ(deltaE94({40, 0, 0}, {60, 0, 0}), 20.0);
    EXPECT_DOUBLE_EQ(deltaE94({60, 0, 0}, {40, 0, 0}), 20.0);
    EXPECT_NEAR(deltaE94({50, 30, 40}, {50, 40, 30}), deltaE94({50, 40, 30}, {50, 30, 40}), 1e-12);
    EXPECT_EQ(deltaE94({50, 30, 40}, {50, 30, 40}), 0.0);
}
