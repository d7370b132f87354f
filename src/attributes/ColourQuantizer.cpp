// See ColourQuantizer.h. Farthest-point clustering (Gonzalez 1985; the
// "minimised maximum intercluster distance" of Xiang 1997 that Dado et al.
// §4.3 use) on the distinct colours in CIELAB with Euclidean distance
// (ΔE*76), seeded with the RGB cube's corners present in the data (pure
// black, white, primaries and secondaries survive exactly). Every point keeps the distance to its nearest centre, so the
// final assignment is exact nearest-centre without another pass.
#include "src/attributes/ColourQuantizer.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include <fmt/core.h>

#include "src/attributes/CieLab.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {
namespace {

// Raw bytes of one value (at most 3 x 8), zero-padded.
struct RawColour {
    std::array<uint64_t, 3> words{};
    bool operator==(const RawColour&) const = default;
};
struct RawColourHash {
    size_t operator()(const RawColour& c) const {
        uint64_t h = c.words[0] * 0x9E3779B97F4A7C15ull ^ c.words[1] * 0xC2B2AE3D27D4EB4Full ^ c.words[2] * 0x165667B19E3779F9ull;
        return size_t(h ^ (h >> 31));
    }
};

// Squared Euclidean distance in CIELAB (all comparisons below are on
// squared distances: no square roots in the inner loops).
double distance2(const Lab& a, const Lab& b) {
    const double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    return d0 * d0 + d1 * d1 + d2 * d2;
}

// A cluster member with its colour inline, so scanning a cluster reads
// memory sequentially.
struct Member {
    Lab lab;
    double dist2;  // squared distance to the cluster's centre (the nearest centre)
    uint32_t point;
};

struct Cluster {
    uint32_t centre;
    std::vector<Member> members;
    double radius2 = 0;  // squared distance of the farthest member
    uint32_t farthest = 0;
};

void updateRadius(Cluster& c) {
    c.radius2 = 0;
    c.farthest = c.centre;
    for (const Member& m : c.members)
        if (m.dist2 > c.radius2) { c.radius2 = m.dist2; c.farthest = m.point; }
}

// Returns, for every point, the index of its cluster centre (a point index).
// `seeds` (point indices) become centres first, in order.
std::vector<uint32_t> farthestPointClustering(const std::vector<Lab>& points, uint64_t maxClusters, const std::vector<uint32_t>& seeds) {
    const uint32_t n = uint32_t(points.size());
    std::vector<Cluster> clusters(1);
    const uint32_t first = seeds.empty() ? 0 : seeds[0];
    clusters[0].centre = first;
    clusters[0].members.resize(n);
    for (uint32_t p = 0; p < n; ++p) clusters[0].members[p] = Member{points[p], distance2(points[p], points[first]), p};
    updateRadius(clusters[0]);
    auto addCentre = [&](uint32_t c) {
        Cluster fresh;
        fresh.centre = c;
        const Lab& centre = points[c];
        for (Cluster& a : clusters) {
            // Triangle inequality: p (|a p| <= radius) can be nearer to c
            // than to a only if |a c| < 2 |a p| <= 2 radius (squared: 4 radius^2).
            if (!(distance2(points[a.centre], centre) < 4.0 * a.radius2)) continue;
            size_t kept = 0;
            for (Member& m : a.members) {
                const double d = distance2(m.lab, centre);
                if (d < m.dist2) {
                    m.dist2 = d;
                    fresh.members.push_back(m);
                } else {
                    a.members[kept++] = m;
                }
            }
            a.members.resize(kept);
            updateRadius(a);
        }
        updateRadius(fresh);
        clusters.push_back(std::move(fresh));
    };
    for (size_t s = 1; s < seeds.size() && clusters.size() < maxClusters; ++s) addCentre(seeds[s]);
    while (clusters.size() < maxClusters) {
        size_t worst = 0;
        for (size_t a = 1; a < clusters.size(); ++a)
            if (clusters[a].radius2 > clusters[worst].radius2) worst = a;
        if (!(clusters[worst].radius2 > 0)) break;  // every distinct colour is a centre
        addCentre(clusters[worst].farthest);
    }
    std::vector<uint32_t> centreOf(n);
    for (const Cluster& c : clusters)
        for (const Member& m : c.members) centreOf[m.point] = c.centre;
    return centreOf;
}

template <typename T>
std::array<double, 3> componentsOf(const uint8_t* value) {
    T v[3];
    std::memcpy(v, value, sizeof(v));
    return {double(v[0]), double(v[1]), double(v[2])};
}

} // namespace

bool isVec3Type(ValueType type) { return type == ValueType::Vec3S || type == ValueType::Vec3D || type == ValueType::Vec3I; }

bool hasColourGridName(const std::string& name) {
    std::string lower(name);
    for (char& ch : lower) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    for (const char* known : {"cd", "color", "colour", "colorgrid", "colourgrid", "rgb"})
        if (lower == known) return true;
    return false;
}

std::array<double, 3> colourOf(const uint8_t* value, ValueType type) {
    switch (type) {
        case ValueType::Vec3S: return componentsOf<float>(value);
        case ValueType::Vec3D: return componentsOf<double>(value);
        case ValueType::Vec3I: {
            const auto c = componentsOf<int32_t>(value);
            return {c[0] / 255.0, c[1] / 255.0, c[2] / 255.0};
        }
        default: throw Error("internal error: colourOf on a non-vec3 value");
    }
}

ColourReport quantiseColours(std::vector<uint8_t>& values, ValueType type, unsigned bits, const std::string& what) {
    if (!isVec3Type(type)) throw Error(what + ": colour quantisation needs a vec3 grid, this one holds " + valueTypeName(type));
    if (bits < 1 || bits > 16) throw Error(what + ": colour bits must be 1..16, got " + std::to_string(bits));
    const unsigned vs = valueSize(type);
    const size_t n = values.size() / vs;
    ColourReport report;
    report.bits = bits;
    report.entries = n;

    // Distinct colours in first-occurrence order, with their counts.
    std::unordered_map<RawColour, uint32_t, RawColourHash> index;
    std::vector<uint32_t> entryColour(n);
    std::vector<RawColour> raws;
    std::vector<uint64_t> counts;
    for (size_t i = 0; i < n; ++i) {
        RawColour key;
        std::memcpy(key.words.data(), &values[i * vs], vs);
        auto [it, inserted] = index.try_emplace(key, uint32_t(raws.size()));
        if (inserted) {
            const auto c = colourOf(&values[i * vs], type);
            for (int k = 0; k < 3; ++k)
                if (!(c[k] >= 0.0 && c[k] <= 1.0)) {
                    const auto raw = type == ValueType::Vec3I ? componentsOf<int32_t>(&values[i * vs]) : c;
                    throw Error(fmt::format("{}: value ({}, {}, {}) is not an sRGB colour (components must be {}); "
                                            "--colour-bits applies to colour grids only (choose them with --colour-grid)",
                                            what, raw[0], raw[1], raw[2], type == ValueType::Vec3I ? "integers in 0..255" : "finite, in [0, 1]"));
                }
            raws.push_back(key);
            counts.push_back(0);
        }
        entryColour[i] = it->second;
        ++counts[it->second];
    }
    report.distinctBefore = raws.size();
    report.distinctAfter = raws.size();
    const uint64_t maxColours = uint64_t(1) << bits;
    if (raws.size() <= maxColours) return report;  // already few enough: exact

    std::vector<Lab> lab(raws.size());
    for (size_t p = 0; p < raws.size(); ++p) lab[p] = srgbToLab(colourOf(reinterpret_cast<const uint8_t*>(raws[p].words.data()), type));
    // The corners of the RGB cube (black, white, primaries, secondaries) are
    // the gamut's extremes and what a viewer notices first: when present
    // they seed the clustering, so they survive exactly.
    std::vector<uint32_t> seeds;
    for (size_t p = 0; p < raws.size(); ++p) {
        const auto c = colourOf(reinterpret_cast<const uint8_t*>(raws[p].words.data()), type);
        if ((c[0] == 0.0 || c[0] == 1.0) && (c[1] == 0.0 || c[1] == 1.0) && (c[2] == 0.0 || c[2] == 1.0)) seeds.push_back(uint32_t(p));
    }
    const std::vector<uint32_t> centre = farthestPointClustering(lab, maxColours, seeds);

    // Errors per distinct colour, weighted by its count.
    std::vector<uint8_t> isCentre(raws.size(), 0);
    double sumDeltaE = 0;
    std::array<double, 3> sumAbs{};
    for (size_t p = 0; p < raws.size(); ++p) {
        const uint32_t c = centre[p];
        isCentre[c] = 1;
        if (c == p) continue;
        const auto a = colourOf(reinterpret_cast<const uint8_t*>(raws[p].words.data()), type);
        const auto b = colourOf(reinterpret_cast<const uint8_t*>(raws[c].words.data()), type);
        for (int k = 0; k < 3; ++k) {
            const double e = std::fabs(a[k] - b[k]) * 255.0;
            sumAbs[k] += e * double(counts[p]);
            report.maxAbsError[k] = std::max(report.maxAbsError[k], e);
        }
        const double de = deltaE94(lab[p], lab[c]);
        sumDeltaE += de * double(counts[p]);
        report.maxDeltaE94 = std::max(report.maxDeltaE94, de);
        report.changed += counts[p];
    }
    report.distinctAfter = uint64_t(std::count(isCentre.begin(), isCentre.end(), uint8_t(1)));
    for (int k = 0; k < 3; ++k) report.meanAbsError[k] = sumAbs[k] / double(n);
    report.meanDeltaE94 = sumDeltaE / double(n);
    for (size_t i = 0; i < n; ++i) {
        const uint32_t c = centre[entryColour[i]];
        if (c != entryColour[i]) std::memcpy(&values[i * vs], raws[c].words.data(), vs);
    }
    return report;
}

} // namespace vdbdag::attributes
