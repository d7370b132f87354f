// CPU tracer against the exact integer reference (brute force over every
// decoded voxel with rational arithmetic): random grids and rays, and the
// adversarial set of issue 4 (axis-parallel rays with 0 and -0.0 direction
// components, rays starting inside or exactly on faces, edges and corners,
// grazing rays, roots spanning 2^24 and 2^32 voxels, non-finite rays).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "src/attributes/PredictedWindows.h"
#include "src/dag/DagBuilder.h"
#include "src/encoding/AttributeLayout.h"
#include "src/encoding/CompactDag.h"
#include "src/format/TraceableValues.h"
#include "src/pipeline/GridCodec.h"
#include "src/trace/DagTracer.h"
#include "src/trace/ExactRayReference.h"
#include "tests/tools/ForgedScenes.h"
#include "tests/unit/TracerTestGrids.h"

using namespace vdbdag;
using trace::Ray;
using trace::RayHit;

namespace {

using vdbdag::testing::compactOf;
using vdbdag::testing::randomTopology;

double dyadic(std::mt19937_64& rng, double lo, double hi, int fractionBits) {
    std::uniform_real_distribution<double> u(lo, hi);
    return std::round(std::ldexp(u(rng), fractionBits)) / std::ldexp(1.0, fractionBits);
}

void expectSameHit(const RayHit& got, const RayHit& want, const Ray& ray, const std::string& label) {
    const std::string where = label + ": ray o=(" + std::to_string(ray.origin[0]) + "," + std::to_string(ray.origin[1]) + "," +
                              std::to_string(ray.origin[2]) + ") d=(" + std::to_string(ray.direction[0]) + "," +
                              std::to_string(ray.direction[1]) + "," + std::to_string(ray.direction[2]) + ")";
    ASSERT_EQ(got.hit, want.hit) << where;
    if (!want.hit) return;
    ASSERT_EQ(got.voxel, want.voxel) << where;
    ASSERT_EQ(got.attribute, want.attribute) << where;
    ASSERT_NEAR(got.t, want.t, 1e-12 * std::max(1.0, std::fabs(want.t))) << where;
    ASSERT_EQ(got.faceAxis, want.faceAxis) << where;
    ASSERT_EQ(got.faceSign, want.faceSign) << where;
}

} // namespace

TEST(CpuTracer, AgreesWithTheExactReferenceOnRandomGridsAndRays) {
    std::mt19937_64 rng(7);
    for (int grid = 0; grid < 6; ++grid) {
        const GridTopology topology = randomTopology(rng, 4, grid % 2 ? -16 : 8);
        const encoding::CompactDag dag = compactOf(topology, grid < 4);
        const trace::DagTracer tracer(dag);
        const trace::ExactRayReference reference(dag);
        int hits = 0;
        for (int i = 0; i < 3000; ++i) {
            Ray ray;
            for (int a = 0; a < 3; ++a) {
                ray.origin[a] = dyadic(rng, -30, 60, i % 2 ? 2 : 10);
                ray.direction[a] = dyadic(rng, -1, 1, i % 3 ? 3 : 12);
            }
            if (i % 7 == 0) ray.direction[i % 3] = (i % 14 == 0) ? -0.0 : 0.0;
            const RayHit want = reference.trace(ray);
            hits += want.hit;
            expectSameHit(tracer.trace(ray), want, ray, "grid " + std::to_string(grid));
        }
        EXPECT_GT(hits, 100) << "the random rays should hit often enough to mean something";
    }
}

TEST(CpuTracer, AxisParallelFaceEdgeCornerAndGrazingRays) {
    std::mt19937_64 rng(11);
    const GridTopology topology = randomTopology(rng, 3, 0);
    const encoding::CompactDag dag = compactOf(topology);
    const trace::DagTracer tracer(dag);
    const trace::ExactRayReference reference(dag);
    const double zeros[2] = {0.0, -0.0};
    int hits = 0;
    for (int i = 0; i < 4000; ++i) {
        Ray ray;
        // Origins on integer lattice points (corners), half-integers (face
        // centres) and mixes (edges), inside and outside the grid.
        for (int a = 0; a < 3; ++a) {
            const int64_t cell = int64_t(rng() % 34) - 5;
            const int pick = int(rng() % 3);
            ray.origin[a] = double(cell) + (pick == 0 ? 0.0 : pick == 1 ? 0.5 : 0.25);
        }
        // Directions: axis-parallel (two zero components, signed zeros), along
        // face diagonals (one zero: grazing a face plane when the origin is on it)
        // and exact body diagonals (crossing edges and corners exactly).
        const int axis = int(rng() % 3);
        const int pattern = int(rng() % 3);
        for (int a = 0; a < 3; ++a) {
            const double sign = (rng() & 1) ? 1.0 : -1.0;
            if (pattern == 0) ray.direction[a] = a == axis ? sign * double(1 + rng() % 3) : zeros[rng() & 1];
            else if (pattern == 1) ray.direction[a] = a == axis ? zeros[rng() & 1] : sign;
            else ray.direction[a] = sign * (rng() % 2 ? 1.0 : 0.5);
        }
        const RayHit want = reference.trace(ray);
        hits += want.hit;
        expectSameHit(tracer.trace(ray), want, ray, "adversarial");
    }
    EXPECT_GT(hits, 400);
}

TEST(CpuTracer, RootsSpanning2To24And2To32Voxels) {
    for (const int64_t far : {int64_t(1) << 23, int64_t(std::numeric_limits<int32_t>::max()) - 3}) {
        GridTopology topology;
        const int32_t hiCorner = int32_t(far & ~int64_t(3));
        const int32_t loCorner = int32_t(-(far + 1) & ~int64_t(3));
        topology.bricks.push_back({loCorner, loCorner, loCorner, 0x8000000000000001ull});
        topology.bricks.push_back({hiCorner, hiCorner, hiCorner, 0x8000000000000001ull});
        topology.bricks.push_back({0, 0, 0, 0xFFFFull});
        const encoding::CompactDag dag = compactOf(topology);
        ASSERT_GE(dag.log2Size, far > (1 << 24) ? 32 : 24);
        const trace::DagTracer tracer(dag);
        const trace::ExactRayReference reference(dag);
        std::vector<Ray> rays;
        for (int k = 0; k < 3; ++k) {  // straight at each occupied voxel from outside, along every axis
            const double c[3][3] = {{double(loCorner), double(loCorner), double(loCorner)},
                                    {double(hiCorner + 3), double(hiCorner + 3), double(hiCorner + 3)},
                                    {1.0, 1.0, 0.0}};
            for (int a = 0; a < 3; ++a)
                for (double s : {1.0, -1.0}) {
                    Ray ray;
                    for (int b = 0; b < 3; ++b) ray.origin[b] = c[k][b] + 0.5, ray.direction[b] = 0.0;
                    ray.origin[a] = c[k][a] + 0.5 - s * 1000.0;
                    ray.direction[a] = s;
                    rays.push_back(ray);
                }
        }
        // Diagonal across the whole root: from beyond the low corner to the high one.
        Ray diagonal;
        for (int b = 0; b < 3; ++b) diagonal.origin[b] = double(loCorner) - 7.25, diagonal.direction[b] = 1.0;
        rays.push_back(diagonal);
        Ray back = diagonal;
        for (int b = 0; b < 3; ++b) back.origin[b] = double(hiCorner) + 9.75, back.direction[b] = -1.0;
        rays.push_back(back);
        for (const Ray& ray : rays) {
            const RayHit want = reference.trace(ray);
            ASSERT_TRUE(want.hit) << ray.origin[0] << " " << ray.origin[1] << " " << ray.origin[2] << " d " << ray.direction[0] << ray.direction[1] << ray.direction[2];
            const RayHit got = tracer.trace(ray);
            expectSameHit(got, want, ray, "root 2^" + std::to_string(dag.log2Size));
            EXPECT_LT(got.steps, 64u * dag.log2Size) << "a hierarchical walk crosses O(depth) empty nodes per level";
        }
    }
}

TEST(CpuTracer, TheUnitCubeCaseOfPublicVoxelRayCasters) {
    // One voxel, cell space [0,1)^3; origin (0.49, 0.49, -1), direction (0, 0, 2):
    // it must hit voxel (0,0,0) at t = 0.5 through its -z face.
    GridTopology topology;
    topology.bricks.push_back({0, 0, 0, 1});
    const encoding::CompactDag dag = compactOf(topology);
    const trace::DagTracer tracer(dag);
    Ray ray;
    ray.origin = {0.49, 0.49, -1.0};
    ray.direction = {0.0, 0.0, 2.0};
    const RayHit hit = tracer.trace(ray);
    ASSERT_TRUE(hit.hit);
    EXPECT_EQ(hit.voxel, (std::array<int64_t, 3>{0, 0, 0}));
    EXPECT_EQ(hit.t, 0.5);
    EXPECT_EQ(hit.faceAxis, 2);
    EXPECT_EQ(hit.faceSign, -1);
    ray.origin = {0.99999999, 0.0, -1.0};  // still inside the voxel's x range
    EXPECT_TRUE(tracer.trace(ray).hit);
    ray.origin = {1.0, 0.0, -1.0};  // on the far x face: outside (half-open voxels)
    EXPECT_FALSE(tracer.trace(ray).hit);
}

TEST(CpuTracer, NonFiniteAndDegenerateRaysMissWithoutLooping) {
    std::mt19937_64 rng(3);
    const encoding::CompactDag dag = compactOf(randomTopology(rng, 3));
    const trace::DagTracer tracer(dag);
    const double bad[] = {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    for (double b : bad)
        for (int a = 0; a < 6; ++a) {
            Ray ray;
            ray.origin = {1.5, 2.5, -3};
            ray.direction = {0.1, 0.2, 1};
            (a < 3 ? ray.origin : ray.direction)[a % 3] = b;
            EXPECT_FALSE(tracer.trace(ray).hit);
        }
    Ray still;  // zero direction: a point query at tMin
    still.direction = {0.0, -0.0, 0.0};
    still.origin = {-5, -5, -5};
    EXPECT_FALSE(tracer.trace(still).hit);
    const trace::ExactRayReference reference(dag);
    for (int i = 0; i < 200; ++i) {
        still.origin = {double(rng() % 24) + 0.5, double(rng() % 24) + 0.5, double(rng() % 24) + 0.5};
        expectSameHit(tracer.trace(still), reference.trace(still), still, "point query");
    }
    Ray bounded;  // tMax stops the ray before the grid
    bounded.origin = {4.5, 4.5, -100};
    bounded.direction = {0, 0, 1};
    bounded.tMax = 50;
    EXPECT_FALSE(tracer.trace(bounded).hit);
}

TEST(CpuTracer, SegmentWalkVisitsEveryOccupiedBoxInOrderAndPointQueriesAgree) {
    std::mt19937_64 rng(21);
    const encoding::CompactDag dag = compactOf(randomTopology(rng, 4, -8));
    const trace::DagTracer tracer(dag);
    const trace::ExactRayReference reference(dag);
    size_t segments = 0;
    for (int i = 0; i < 1500; ++i) {
        Ray ray;
        for (int a = 0; a < 3; ++a) {
            ray.origin[a] = dyadic(rng, -20, 40, 6);
            ray.direction[a] = dyadic(rng, -1, 1, 4);
        }
        if (i % 5 == 0) ray.direction[i % 3] = 0.0;
        std::vector<RayHit> got;
        std::vector<double> leave;
        tracer.forEachSegment(ray, [&](const RayHit& box, double tLeave) {
            got.push_back(box);
            leave.push_back(tLeave);
            return false;
        });
        const std::vector<RayHit> want = reference.traceAll(ray);
        ASSERT_EQ(got.size(), want.size());
        for (size_t k = 0; k < want.size(); ++k) {
            expectSameHit(got[k], want[k], ray, "segment " + std::to_string(k));
            EXPECT_GT(leave[k], got[k].t);
            if (k + 1 < want.size()) { EXPECT_LE(leave[k], want[k + 1].t); }
        }
        segments += want.size();
    }
    EXPECT_GT(segments, 500u);
    for (int i = 0; i < 20000; ++i) {
        const std::array<int64_t, 3> voxel{int64_t(rng() % 40) - 12, int64_t(rng() % 40) - 12, int64_t(rng() % 40) - 12};
        ASSERT_EQ(tracer.find(voxel), reference.find(voxel));
    }
}

// An atlas through the whole path a tracer reads labels by: a dense box of
// Voronoi labels encoded by the pipeline, its uniform 8^3 blocks tiles (its
// window coded as labels, coding 18: tiles as neighbours), the traceable
// palettes rebuilt from that window (the
// attributes the encoder kept dropped first), and the tracer's point lookup:
// every voxel's entry holds the label the generating function gives.
TEST(DagTracer, FindsEveryVoxelOfAnAtlasWithItsLabel) {
    const auto label = [](int x, int y, int z) {
        static constexpr int kSeeds[6][3] = {{4, 6, 2}, {40, 8, 24}, {18, 34, 12}, {44, 36, 4}, {10, 20, 28}, {28, 2, 18}};
        int best = 0, bestD = 1 << 30;
        for (int s = 0; s < 6; ++s) {
            const int d = (x - kSeeds[s][0]) * (x - kSeeds[s][0]) + (y - kSeeds[s][1]) * (y - kSeeds[s][1]) + (z - kSeeds[s][2]) * (z - kSeeds[s][2]);
            if (d < bestD) bestD = d, best = s;
        }
        return int32_t(1000 * best - 2500);
    };
    const GridRecord atlas = vdbdag::testing::labelBox("atlas", 12, 10, 8, label, true);
    ASSERT_FALSE(atlas.topology.tiles.empty());
    format::EncodedGrid encoded = pipeline::encodeGrid(atlas);
    EXPECT_EQ(encoding::decodedSize(encoded.active.dag).emittedTiles, atlas.topology.tiles.size());
    const attributes::ValueWindowsPayload& windows = encoded.active.valueWindows;
    ASSERT_TRUE(windows.predicted);
    const attributes::WindowDirectory dir =
        attributes::readPredictedWindowDirectory(windows.bytes, 4, encoding::attributeLayout(encoded.active.dag), "atlas");
    ASSERT_EQ(dir.windows.size(), 1u);
    ASSERT_EQ(windows.bytes[size_t(dir.windows[0].offset)], attributes::detail::kTiledLabelCoding);
    encoded.active.attributes.clear();  // the palettes from the window itself
    const std::vector<uint8_t> values = format::traceableValues(encoded).decodeAll();
    const trace::DagTracer tracer(encoded.active.dag);
    for (int z = 0; z < 32; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 48; ++x) {
                const std::optional<uint64_t> entry = tracer.find({x, y, z});
                ASSERT_TRUE(entry.has_value()) << x << " " << y << " " << z;
                ASSERT_LT(*entry * 4 + 4, values.size() + 1);
                int32_t got;
                std::memcpy(&got, values.data() + *entry * 4, 4);
                ASSERT_EQ(got, label(x, y, z)) << x << " " << y << " " << z;
            }
    EXPECT_FALSE(tracer.find({48, 0, 0}).has_value());
}
