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
#include <tbb/parallel_for.h>

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

// A stored colour: its raw value (of the grid's type) and its CIELAB.
struct Representative {
    Lab lab;
    RawColour raw;
    bool fixed;  // a seed (RGB cube corner): never moved
};

// sRGB in [0, 1] -> raw value of `type` (vec3i: rounded to 0..255).
RawColour rawOf(const Rgb& rgb, ValueType type) {
    RawColour raw;
    double c[3];
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(rgb[k], 0.0, 1.0);
    if (type == ValueType::Vec3S) {
        const float v[3] = {float(c[0]), float(c[1]), float(c[2])};
        std::memcpy(raw.words.data(), v, sizeof(v));
    } else if (type == ValueType::Vec3D) {
        std::memcpy(raw.words.data(), c, sizeof(c));
    } else {
        const int32_t v[3] = {int32_t(std::lround(c[0] * 255.0)), int32_t(std::lround(c[1] * 255.0)), int32_t(std::lround(c[2] * 255.0))};
        std::memcpy(raw.words.data(), v, sizeof(v));
    }
    return raw;
}

// Uniform grid over CIELAB holding the representatives, for nearest queries.
class CentreGrid {
public:
    CentreGrid(const std::vector<Representative>& reps, double cell) {
        lo_ = reps[0].lab;
        Lab hi = reps[0].lab;
        for (const auto& r : reps)
            for (int k = 0; k < 3; ++k) { lo_[k] = std::min(lo_[k], r.lab[k]); hi[k] = std::max(hi[k], r.lab[k]); }
        double extent = 0;
        for (int k = 0; k < 3; ++k) extent = std::max(extent, hi[k] - lo_[k]);
        cell_ = std::max({cell, extent / 64.0, 1e-6});
        for (int k = 0; k < 3; ++k) dim_[k] = int(std::floor((hi[k] - lo_[k]) / cell_)) + 1;
        start_.assign(size_t(dim_[0]) * dim_[1] * dim_[2] + 1, 0);
        for (const auto& r : reps) ++start_[cellOf(r.lab) + 1];
        for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        items_.resize(reps.size());
        std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
        for (uint32_t i = 0; i < reps.size(); ++i) items_[fill[cellOf(reps[i].lab)]++] = i;  // increasing index per cell
    }
    // Nearest representative to `p`, starting from `best` at squared
    // distance `best2`; only strictly nearer ones replace it.
    uint32_t nearest(const Lab& p, const std::vector<Representative>& reps, uint32_t best, double best2) const {
        const double r = std::sqrt(best2);
        int from[3], to[3];
        for (int k = 0; k < 3; ++k) {
            from[k] = std::clamp(int(std::floor((p[k] - r - lo_[k]) / cell_)), 0, dim_[k] - 1);
            to[k] = std::clamp(int(std::floor((p[k] + r - lo_[k]) / cell_)), 0, dim_[k] - 1);
        }
        for (int z = from[2]; z <= to[2]; ++z)
            for (int y = from[1]; y <= to[1]; ++y)
                for (int x = from[0]; x <= to[0]; ++x) {
                    const size_t c = (size_t(z) * dim_[1] + y) * dim_[0] + x;
                    for (uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
                        const double d = distance2(p, reps[items_[k]].lab);
                        if (d < best2) { best2 = d; best = items_[k]; }
                    }
                }
        return best;
    }

private:
    size_t cellOf(const Lab& p) const {
        int c[3];
        for (int k = 0; k < 3; ++k) c[k] = std::clamp(int(std::floor((p[k] - lo_[k]) / cell_)), 0, dim_[k] - 1);
        return (size_t(c[2]) * dim_[1] + c[1]) * dim_[0] + c[0];
    }
    Lab lo_{};
    double cell_ = 1;
    int dim_[3] = {1, 1, 1};
    std::vector<uint32_t> start_, items_;
};

// k-means (Lloyd) passes that keep the farthest-point guarantee: a centre
// moves to its cluster's weighted CIELAB mean (converted to a storable
// value) only if every member stays within the clustering's maximum
// radius R; points then move only to strictly nearer centres. So the
// maximum ΔE*76 never exceeds R while the mean error drops. Seeds stay.
void refineColourCentres(const std::vector<Lab>& points, const std::vector<uint64_t>& counts, ValueType type, unsigned passes,
                         std::vector<Representative>& reps, std::vector<uint32_t>& assign) {
    const size_t n = points.size();
    double radius2 = 0;
    for (size_t p = 0; p < n; ++p) radius2 = std::max(radius2, distance2(points[p], reps[assign[p]].lab));
    for (unsigned pass = 0; pass < passes && radius2 > 0; ++pass) {
        // Members of each representative (counting sort, increasing point index).
        std::vector<uint32_t> first(reps.size() + 1, 0), members(n);
        for (size_t p = 0; p < n; ++p) ++first[assign[p] + 1];
        for (size_t r = 1; r <= reps.size(); ++r) first[r] += first[r - 1];
        {
            std::vector<uint32_t> fill(first.begin(), first.end() - 1);
            for (uint32_t p = 0; p < n; ++p) members[fill[assign[p]]++] = p;
        }
        bool moved = false;
        for (size_t r = 0; r < reps.size(); ++r) {
            if (reps[r].fixed || first[r] == first[r + 1]) continue;
            Lab mean{0, 0, 0};
            double weight = 0;
            for (uint32_t k = first[r]; k < first[r + 1]; ++k) {
                const uint32_t p = members[k];
                for (int c = 0; c < 3; ++c) mean[c] += points[p][c] * double(counts[p]);
                weight += double(counts[p]);
            }
            for (int c = 0; c < 3; ++c) mean[c] /= weight;
            const RawColour raw = rawOf(labToSrgb(mean), type);
            if (raw == reps[r].raw) continue;
            const Lab lab = srgbToLab(colourOf(reinterpret_cast<const uint8_t*>(raw.words.data()), type));
            bool within = true;
            for (uint32_t k = first[r]; k < first[r + 1] && within; ++k) within = distance2(points[members[k]], lab) <= radius2;
            if (!within) continue;
            reps[r].raw = raw;
            reps[r].lab = lab;
            moved = true;
        }
        if (!moved) break;
        const CentreGrid grid(reps, std::sqrt(radius2) / 2.0);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t p = range.begin(); p != range.end(); ++p)
                assign[p] = grid.nearest(points[p], reps, assign[p], distance2(points[p], reps[assign[p]].lab));
        });
    }
}

} // namespace

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

ColourReport quantiseColours(std::vector<uint8_t>& values, ValueType type, unsigned bits, const std::string& what, unsigned refinePasses) {
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
    const std::vector<uint32_t> centreOfPoint = farthestPointClustering(lab, maxColours, seeds);

    // Representatives: the farthest-point centres (input colours), then
    // refined (refineColourCentres) without exceeding their maximum error.
    std::vector<uint32_t> assign(raws.size());
    std::vector<Representative> reps;
    {
        std::vector<uint32_t> repIndex(raws.size(), UINT32_MAX);
        std::vector<uint8_t> isSeed(raws.size(), 0);
        for (uint32_t sd : seeds) isSeed[sd] = 1;
        for (size_t p = 0; p < raws.size(); ++p) {
            const uint32_t c = centreOfPoint[p];
            if (repIndex[c] == UINT32_MAX) {
                repIndex[c] = uint32_t(reps.size());
                reps.push_back(Representative{lab[c], raws[c], isSeed[c] != 0});
            }
            assign[p] = repIndex[c];
        }
    }
    refineColourCentres(lab, counts, type, refinePasses, reps, assign);

    // Errors per distinct colour, weighted by its count, against the value
    // actually stored.
    std::unordered_map<RawColour, uint32_t, RawColourHash> used;
    double sumDeltaE = 0;
    std::array<double, 3> sumAbs{};
    for (size_t p = 0; p < raws.size(); ++p) {
        const Representative& r = reps[assign[p]];
        used.try_emplace(r.raw, 0);
        if (r.raw == raws[p]) continue;
        const auto a = colourOf(reinterpret_cast<const uint8_t*>(raws[p].words.data()), type);
        const auto b = colourOf(reinterpret_cast<const uint8_t*>(r.raw.words.data()), type);
        for (int k = 0; k < 3; ++k) {
            const double e = std::fabs(a[k] - b[k]) * 255.0;
            sumAbs[k] += e * double(counts[p]);
            report.maxAbsError[k] = std::max(report.maxAbsError[k], e);
        }
        const double de = deltaE94(lab[p], r.lab);
        sumDeltaE += de * double(counts[p]);
        report.maxDeltaE94 = std::max(report.maxDeltaE94, de);
        report.changed += counts[p];
    }
    report.distinctAfter = used.size();
    for (int k = 0; k < 3; ++k) report.meanAbsError[k] = sumAbs[k] / double(n);
    report.meanDeltaE94 = sumDeltaE / double(n);
    for (size_t i = 0; i < n; ++i) {
        const Representative& r = reps[assign[entryColour[i]]];
        if (!(r.raw == raws[entryColour[i]])) std::memcpy(&values[i * vs], r.raw.words.data(), vs);
    }
    return report;
}

} // namespace vdbdag::attributes
