// The `rays` group (issue 7 part 2 = issue 4's adversarial set): the CPU
// tracer (src/trace/DagTracer.h) against the exact rational reference
// (src/trace/ExactRayReference.h, a brute-force walk over every decoded box
// without floating point) on grids built here: axis-parallel rays with +0
// and -0 direction components; origins inside the grid and exactly on
// faces, edges and corners; grazing rays along face planes; exact body
// diagonals through edges and corners; random dyadic rays on symmetric and
// plain DAGs; roots spanning 2^24 and 2^32 voxels; the unit-cube case that
// breaks public voxel ray casters (origin (0.49, 0.49, -1), direction
// (0, 0, 2)); NaN, Inf, zero-direction and huge rays. Bounds: zero
// mismatches (hit, voxel, attribute entry, entry face, t within 1e-12
// relative), no NaN t, and bounded steps: a line crosses at most
// 3 x 2^(L-s) + 1 cells of size 2^s inside a root of 2^L, so a walk leaves
// at most 6 x 2^L + L + 1 nodes behind; rays aimed at isolated voxels in
// the huge roots must skip the empty space: fewer than 64 x L steps.
#include <cmath>
#include <limits>
#include <random>

#include <fmt/core.h>

#include "src/dag/DagBuilder.h"
#include "src/encoding/CompactDag.h"
#include "src/selftest/CaseGroups.h"
#include "src/selftest/RayCases.h"
#include "src/trace/DagTracer.h"
#include "src/trace/ExactRayReference.h"

namespace vdbdag::selftest {
namespace {

using trace::Ray;
using trace::RayHit;

encoding::CompactDag compactOf(const GridTopology& topology, bool symmetry) {
    dag::BuildOptions options;
    options.symmetry = symmetry;
    encoding::CompactDag dag = encoding::encodeCompact(dag::buildDag(topology, options), true);
    encoding::validateCompact(dag, "selftest ray grid");
    return dag;
}

// cells^3 cells of 8^3 voxels from `corner`: empty (half), an active 8^3
// tile, or up to 8 random bricks, some of them mirror images of each other
// so a symmetric DAG merges them under reflections.
GridTopology adversarialTopology(uint64_t seed, int cells, int32_t corner) {
    std::mt19937_64 rng(seed);
    GridTopology topology;
    for (int cz = 0; cz < cells; ++cz)
        for (int cy = 0; cy < cells; ++cy)
            for (int cx = 0; cx < cells; ++cx) {
                const int kind = int(rng() % 10);
                const int32_t x = corner + 8 * cx, y = corner + 8 * cy, z = corner + 8 * cz;
                if (kind <= 4) continue;
                if (kind == 5) {
                    topology.tiles.push_back({x, y, z, 3});
                    continue;
                }
                for (int b = 0; b < 8; ++b) {
                    if (rng() % 3 == 0) continue;
                    uint64_t mask = rng() & rng() & rng();
                    if (b >= 4 && (rng() & 1)) mask = 0x0000000000000F01ull << (rng() % 4);  // shifted copies: mirror images
                    if (!mask) mask = 1;
                    topology.bricks.push_back({x + 4 * (b & 1), y + 4 * ((b >> 1) & 1), z + 4 * (b >> 2), mask});
                }
            }
    return topology;
}

std::string rayText(const Ray& r) {
    return fmt::format("o=({},{},{}) d=({},{},{})", r.origin[0], r.origin[1], r.origin[2], r.direction[0], r.direction[1], r.direction[2]);
}

// Compares tracer and reference on every ray; counts mismatches, hits and
// the largest step count.
struct RayTally {
    Checks checks;
    size_t rays = 0, hits = 0, mismatches = 0;
    uint32_t maxSteps = 0;

    void compare(const trace::DagTracer& tracer, const trace::ExactRayReference& reference, const Ray& ray, uint64_t stepBound) {
        ++rays;
        const RayHit want = reference.trace(ray), got = tracer.trace(ray);
        hits += want.hit;
        maxSteps = std::max(maxSteps, got.steps);
        checks.require(got.steps <= stepBound, fmt::format("{}: {} steps > {}", rayText(ray), got.steps, stepBound));
        checks.require(!std::isnan(got.t), fmt::format("{}: t is NaN", rayText(ray)));
        bool same = got.hit == want.hit;
        if (same && want.hit)
            same = got.voxel == want.voxel && got.attribute == want.attribute && got.faceAxis == want.faceAxis && got.faceSign == want.faceSign &&
                   std::fabs(got.t - want.t) <= 1e-12 * std::max(1.0, std::fabs(want.t));
        if (!same) {
            ++mismatches;
            checks.require(false, fmt::format("{}: tracer {} voxel ({},{},{}) t {:.17g} face {}{}; reference {} voxel ({},{},{}) t {:.17g} face {}{}", rayText(ray),
                                              got.hit ? "hit" : "miss", got.voxel[0], got.voxel[1], got.voxel[2], got.t, got.faceSign, got.faceAxis,
                                              want.hit ? "hit" : "miss", want.voxel[0], want.voxel[1], want.voxel[2], want.t, want.faceSign, want.faceAxis));
        }
    }
    Measurement result(const std::string& extra = {}) const {
        return checks.result(fmt::format("{} mismatches / {}", mismatches, rays), fmt::format("{} rays, {} hits, {} mismatches, max {} steps{}", rays, hits, mismatches, maxSteps, extra));
    }
};

uint64_t stepBound(const encoding::CompactDag& dag) { return 6 * (uint64_t(1) << dag.log2Size) + dag.log2Size + 1; }

void addCases(std::vector<SelftestCase>& cases) {
    cases.push_back({"rays", "axis-face-edge-corner-grazing", "0 mismatches",
                     "4000 rays from lattice corners, face and edge points inside and outside a 24^3 grid of bricks and tiles, axis-parallel "
                     "(+0/-0 components), grazing face planes, exact diagonals: 0 mismatches with the exact reference, steps <= 6 x 2^L + L + 1, no NaN",
                     [] {
                         const encoding::CompactDag dag = compactOf(adversarialTopology(11, 3, 0), true);
                         const trace::DagTracer tracer(dag);
                         const trace::ExactRayReference reference(dag);
                         std::mt19937_64 rng(12);
                         const double zeros[2] = {0.0, -0.0};
                         RayTally tally;
                         for (int i = 0; i < 4000; ++i) {
                             Ray ray;
                             for (int a = 0; a < 3; ++a) {  // corners (.0), face centres (.5) and edges (mixes), inside and outside
                                 const int pick = int(rng() % 3);
                                 ray.origin[a] = double(int64_t(rng() % 34) - 5) + (pick == 0 ? 0.0 : pick == 1 ? 0.5 : 0.25);
                             }
                             const int axis = int(rng() % 3), pattern = int(rng() % 3);
                             for (int a = 0; a < 3; ++a) {
                                 const double sign = (rng() & 1) ? 1.0 : -1.0;
                                 if (pattern == 0) ray.direction[a] = a == axis ? sign * double(1 + rng() % 3) : zeros[rng() & 1];  // axis-parallel
                                 else if (pattern == 1) ray.direction[a] = a == axis ? zeros[rng() & 1] : sign;                      // in a face plane
                                 else ray.direction[a] = sign * (rng() % 2 ? 1.0 : 0.5);                                             // through edges and corners
                             }
                             tally.compare(tracer, reference, ray, stepBound(dag));
                         }
                         tally.checks.require(tally.hits >= 400, fmt::format("only {} hits: the set no longer tests much", tally.hits));
                         return tally.result(fmt::format(" (bound {})", stepBound(dag)));
                     }});

    cases.push_back({"rays", "random-dyadic", "0 mismatches",
                     "4 grids (symmetric and plain DAGs, positive and negative corners) x 1500 random dyadic rays, some with +0/-0 "
                     "components: 0 mismatches, steps <= 6 x 2^L + L + 1, no NaN",
                     [] {
                         RayTally tally;
                         std::mt19937_64 rng(13);
                         auto dyadic = [&](double lo, double hi, int fractionBits) {
                             std::uniform_real_distribution<double> u(lo, hi);
                             return std::round(std::ldexp(u(rng), fractionBits)) / std::ldexp(1.0, fractionBits);
                         };
                         for (int g = 0; g < 4; ++g) {
                             const encoding::CompactDag dag = compactOf(adversarialTopology(20 + g, 4, g % 2 ? -16 : 8), g < 2);
                             const trace::DagTracer tracer(dag);
                             const trace::ExactRayReference reference(dag);
                             for (int i = 0; i < 1500; ++i) {
                                 Ray ray;
                                 for (int a = 0; a < 3; ++a) {
                                     ray.origin[a] = dyadic(-30, 60, i % 2 ? 2 : 10);
                                     ray.direction[a] = dyadic(-1, 1, i % 3 ? 3 : 12);
                                 }
                                 if (i % 7 == 0) ray.direction[i % 3] = (i % 14 == 0) ? -0.0 : 0.0;
                                 tally.compare(tracer, reference, ray, stepBound(dag));
                             }
                         }
                         return tally.result();
                     }});

    for (const int log2Far : {24, 32}) {
        cases.push_back({"rays", fmt::format("root-2^{}", log2Far), "0 mismatches",
                         fmt::format("voxels at both ends of a root spanning 2^{} voxels and near the origin: rays along every axis at each, and the "
                                     "whole diagonal both ways: 0 mismatches, < 64 x L steps (empty space skipped), no NaN",
                                     log2Far),
                         [log2Far] {
                             const int64_t far = log2Far == 24 ? (int64_t(1) << 23) : int64_t(std::numeric_limits<int32_t>::max()) - 3;
                             GridTopology topology;
                             const int32_t hi = int32_t(far & ~int64_t(3)), lo = int32_t(-(far + 1) & ~int64_t(3));
                             topology.bricks.push_back({lo, lo, lo, 0x8000000000000001ull});
                             topology.bricks.push_back({hi, hi, hi, 0x8000000000000001ull});
                             topology.bricks.push_back({0, 0, 0, 0xFFFFull});
                             const encoding::CompactDag dag = compactOf(topology, true);
                             const trace::DagTracer tracer(dag);
                             const trace::ExactRayReference reference(dag);
                             RayTally tally;
                             tally.checks.require(dag.log2Size >= log2Far, fmt::format("root only 2^{}", dag.log2Size));
                             const uint64_t bound = 64u * dag.log2Size;
                             const double targets[3][3] = {{double(lo), double(lo), double(lo)}, {double(hi + 3), double(hi + 3), double(hi + 3)}, {1, 1, 0}};
                             for (const auto& c : targets)
                                 for (int a = 0; a < 3; ++a)
                                     for (double s : {1.0, -1.0}) {
                                         Ray ray;
                                         for (int b = 0; b < 3; ++b) ray.origin[b] = c[b] + 0.5, ray.direction[b] = b == a ? s : (s > 0 ? 0.0 : -0.0);
                                         ray.origin[a] = c[a] + 0.5 - s * 1000.0;
                                         tally.compare(tracer, reference, ray, bound);
                                     }
                             Ray diagonal;
                             for (int b = 0; b < 3; ++b) diagonal.origin[b] = double(lo) - 7.25, diagonal.direction[b] = 1.0;
                             tally.compare(tracer, reference, diagonal, bound);
                             for (int b = 0; b < 3; ++b) diagonal.origin[b] = double(hi) + 9.75, diagonal.direction[b] = -1.0;
                             tally.compare(tracer, reference, diagonal, bound);
                             tally.checks.require(tally.hits == tally.rays, fmt::format("{} of {} aimed rays hit", tally.hits, tally.rays));
                             return tally.result(fmt::format(" (bound {}, root 2^{})", bound, dag.log2Size));
                         }});
    }

    cases.push_back({"rays", "unit-cube-0.49", "t = 0.5, 0 mismatches",
                     "one voxel [0,1)^3, origin (0.49, 0.49, -1), direction (0, 0, 2): hit voxel (0,0,0) at t = 0.5 through its -z face; "
                     "x = 0.99999999 and -0 hit, x = 1 and -1e-9 miss (half-open voxel); dyadic variants of x and y agree with the exact reference",
                     [] {
                         GridTopology topology;
                         topology.bricks.push_back({0, 0, 0, 1});
                         const encoding::CompactDag dag = compactOf(topology, true);
                         const trace::DagTracer tracer(dag);
                         const trace::ExactRayReference reference(dag);
                         RayTally tally;
                         Ray ray;
                         ray.origin = {0.49, 0.49, -1.0};
                         ray.direction = {0.0, 0.0, 2.0};
                         const RayHit hit = tracer.trace(ray);
                         tally.checks.require(hit.hit && hit.voxel == std::array<int64_t, 3>{0, 0, 0} && hit.t == 0.5 && hit.faceAxis == 2 && hit.faceSign == -1,
                                              fmt::format("hit {} voxel ({},{},{}) t {} face {}{}", hit.hit, hit.voxel[0], hit.voxel[1], hit.voxel[2], hit.t,
                                                          hit.faceSign, hit.faceAxis));
                         // Closed form (not dyadic, so the reference cannot take them): inside iff 0 <= x < 1.
                         for (double x : {0.99999999, 1.0, -0.0, -1e-9, 0.49}) {
                             ray.origin[0] = x;
                             const bool inside = x >= 0.0 && x < 1.0;
                             const RayHit h = tracer.trace(ray);
                             tally.checks.require(h.hit == inside && (!h.hit || h.t == 0.5), fmt::format("x = {}: hit {} t {}, expected hit {} t 0.5", x, h.hit, h.t, inside));
                         }
                         // Dyadic variants on the voxel's faces, edges and just inside or outside them.
                         const double eps = std::ldexp(1.0, -16);
                         for (double x : {0.0, -0.0, 0.5, 1.0 - eps, 1.0, -eps})
                             for (double y : {0.0, 0.5, 1.0 - eps, 1.0, -eps})
                                 for (double dz : {2.0, 1.0, -1.0}) {
                                     Ray r;
                                     r.origin = {x, y, dz > 0 ? -1.0 : 2.0};
                                     r.direction = {0.0, -0.0, dz};
                                     tally.compare(tracer, reference, r, stepBound(dag));
                                 }
                         return tally.result(fmt::format("; the 0.49 ray: t = {} through face {}{}", hit.t, hit.faceSign < 0 ? "-" : "+",
                                                         "xyz"[std::max<int>(0, hit.faceAxis)]));
                     }});

    cases.push_back({"rays", "nan-inf-degenerate", "no NaN, no false hit",
                     "NaN and +-Inf in each origin and direction component, zero and -0 directions, huge origins (1e300) and tiny directions "
                     "(1e-300), tMin > tMax: no hit where the ray is undefined, no NaN t, steps <= 6 x 2^L + L + 1; zero-direction point "
                     "queries agree with the exact reference",
                     [] {
                         const encoding::CompactDag dag = compactOf(adversarialTopology(31, 3, 0), true);
                         const trace::DagTracer tracer(dag);
                         const trace::ExactRayReference reference(dag);
                         RayTally tally;
                         const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
                         size_t undefined = 0;
                         for (double bad : {nan, inf, -inf, -nan})
                             for (int a = 0; a < 6; ++a) {
                                 Ray ray;
                                 ray.origin = {1.5, 2.5, -3};
                                 ray.direction = {0.1, 0.2, 1};
                                 (a < 3 ? ray.origin : ray.direction)[a % 3] = bad;
                                 const RayHit got = tracer.trace(ray);
                                 ++undefined;
                                 tally.checks.require(!got.hit, fmt::format("{}: reported a hit", rayText(ray)));
                                 tally.checks.require(got.steps <= stepBound(dag), fmt::format("{}: {} steps", rayText(ray), got.steps));
                             }
                         for (const auto& [o, d] : std::initializer_list<std::pair<std::array<double, 3>, std::array<double, 3>>>{
                                  {{1e300, 2.5, 2.5}, {-1, 0, 0}}, {{-1e300, -1e300, 1e300}, {1, 1, -1}}, {{2.5, 2.5, -1e6}, {1e-300, 0, 1}},
                                  {{2.5, 2.5, 2.5}, {1e-300, -1e-300, 1e-300}}, {{2.5, 2.5, -4}, {0, 0, 1e300}}}) {
                             Ray ray;
                             ray.origin = o;
                             ray.direction = d;
                             const RayHit got = tracer.trace(ray);
                             ++undefined;
                             tally.checks.require(!std::isnan(got.t) && got.steps <= stepBound(dag), fmt::format("{}: t {} steps {}", rayText(ray), got.t, got.steps));
                         }
                         Ray reversed;
                         reversed.origin = {4.5, 4.5, -10};
                         reversed.tMin = 50;
                         reversed.tMax = 10;
                         tally.checks.require(!tracer.trace(reversed).hit, "tMin > tMax reported a hit");
                         std::mt19937_64 rng(32);
                         for (int i = 0; i < 300; ++i) {  // zero (and -0) direction: a point query at tMin
                             Ray still;
                             still.direction = {0.0, -0.0, i % 2 ? -0.0 : 0.0};
                             still.origin = {double(rng() % 28) - 2 + 0.5 * double(i % 3), double(rng() % 28) - 2, double(rng() % 28) - 2 + 0.25};
                             tally.compare(tracer, reference, still, stepBound(dag));
                         }
                         return tally.result(fmt::format(" + {} undefined or huge rays without NaN or a hit where undefined", undefined + 1));
                     }});
}

} // namespace

Measurement compareRays(const encoding::CompactDag& traced, const encoding::CompactDag& reference, std::span<const Ray> rays, uint64_t stepBound) {
    const trace::DagTracer tracer(traced);
    const trace::ExactRayReference exact(reference);
    RayTally tally;
    for (const Ray& ray : rays) tally.compare(tracer, exact, ray, stepBound);
    return tally.result();
}

void addRayCases(std::vector<SelftestCase>& cases) { addCases(cases); }

} // namespace vdbdag::selftest
