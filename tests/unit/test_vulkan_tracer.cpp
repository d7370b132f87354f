// The Vulkan tracer (gpu/VulkanTracer, gpu/shaders/trace.comp) against the
// CPU reference tracer and the exact integer reference, on a real device
// (lavapipe here): over 10^6 rays in total on random grids with tiles and
// mirrored bricks, the generated samples and the level sets of
// ../shared/data (camera and random rays; first hit and zero crossing) the
// two tracers return the same hit flag, voxel, attribute and face, and
// bit-identical t; the adversarial rays of test_tracer.cpp (axis-parallel
// with +-0 components, on faces, edges and corners, grazing, roots spanning
// 2^24 and 2^32) agree with ExactRayReference; rendered images of a level-set
// sphere (with shadows, with and without stored ONV normals), a sphere shell
// shaded by a normal grid's ONV normals and a fog sphere match the CPU
// renderer's (the other shadings: test_vulkan_shadings.cpp).
// Every test skips cleanly when no Vulkan device exists.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include "tests/unit/BuildPaths.h"
#include "gpu/VulkanContext.h"
#include "tests/unit/VulkanTestSupport.h"
#include "gpu/VulkanTracer.h"
#include "src/attributes/OctahedralNormal.h"
#include "src/dag/DagBuilder.h"
#include "src/encoding/CompactDag.h"
#include "src/pipeline/GridCodec.h"
#include "src/trace/CpuRenderer.h"
#include "src/trace/DagTracer.h"
#include "src/trace/ExactRayReference.h"
#include "tests/unit/TracerTestGrids.h"
#include "src/trace/SurfaceHit.h"
#include "src/util/Error.h"
#include "vdb_bridge/VdbImport.h"

using namespace vdbdag;
using trace::Ray;
using trace::RayHit;
using vdbdag::testing::context;
using vdbdag::testing::encodeVdbGrid;
using vdbdag::testing::expectSameImage;
using vdbdag::testing::importVdbGrids;

namespace {

namespace fs = std::filesystem;

using vdbdag::testing::compactOf;
using vdbdag::testing::randomTopology;

trace::RenderGrid geometryOnly(const encoding::CompactDag& dag) {
    trace::RenderGrid grid;
    grid.dag = &dag;
    return grid;
}

double dyadic(std::mt19937_64& rng, double lo, double hi, int fractionBits) {
    std::uniform_real_distribution<double> u(lo, hi);
    return std::round(std::ldexp(u(rng), fractionBits)) / std::ldexp(1.0, fractionBits);
}

std::string describe(const Ray& ray) {
    char text[256];
    std::snprintf(text, sizeof text, "ray o=(%.17g,%.17g,%.17g) d=(%.17g,%.17g,%.17g)", ray.origin[0], ray.origin[1], ray.origin[2],
                  ray.direction[0], ray.direction[1], ray.direction[2]);
    return text;
}

// Counts disagreements (and reports the first few) between GPU and reference hits.
size_t countMismatches(std::span<const RayHit> got, std::span<const RayHit> want, std::span<const Ray> rays, const std::string& label,
                       bool exactT = true) {
    size_t bad = 0;
    for (size_t i = 0; i < want.size(); ++i) {
        const RayHit &g = got[i], &w = want[i];
        bool same = g.hit == w.hit;
        if (same && w.hit) {
            same = g.voxel == w.voxel && g.attribute == w.attribute && g.faceAxis == w.faceAxis && g.faceSign == w.faceSign &&
                   g.lodLevel == w.lodLevel && (exactT ? g.t == w.t : std::fabs(g.t - w.t) <= 1e-12 * std::max(1.0, std::fabs(w.t)));
        }
        if (!same && ++bad <= 5)
            ADD_FAILURE() << label << ": " << describe(rays[i]) << " gpu hit=" << g.hit << " voxel=(" << g.voxel[0] << "," << g.voxel[1] << ","
                          << g.voxel[2] << ") t=" << g.t << " attr=" << g.attribute << " face=" << int(g.faceAxis) << "/" << int(g.faceSign)
                          << " | want hit=" << w.hit << " voxel=(" << w.voxel[0] << "," << w.voxel[1] << "," << w.voxel[2] << ") t=" << w.t
                          << " attr=" << w.attribute << " face=" << int(w.faceAxis) << "/" << int(w.faceSign);
    }
    return bad;
}

std::vector<RayHit> cpuHits(const trace::DagTracer& tracer, std::span<const Ray> rays) {
    std::vector<RayHit> hits(rays.size());
    tracer.traceBatch(rays, hits);
    return hits;
}

std::vector<RayHit> cpuSurfaceHits(const trace::RenderGrid& grid, const trace::DagTracer& tracer, std::span<const Ray> rays) {
    std::vector<RayHit> hits(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) hits[i] = trace::firstSurfaceHit(grid, tracer, rays[i]);
    return hits;
}

// Camera rays over the grid's default framing plus random rays through its box.
std::vector<Ray> sceneRays(const trace::RenderGrid& grid, int width, int height, size_t randomCount, uint64_t seed) {
    std::vector<Ray> rays;
    const trace::GridFrame frame(grid.indexToWorld);
    const trace::Camera camera = trace::frameBounds(frame, grid.cellLo, grid.cellHi, width, height);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            glm::dvec3 eye, dir;
            camera.pixelRay(x, y, eye, dir);
            rays.push_back(frame.toCellRay(eye, dir));
        }
    std::mt19937_64 rng(seed);
    for (size_t i = 0; i < randomCount; ++i) {
        Ray ray;
        for (int a = 0; a < 3; ++a) {
            const double extent = grid.cellHi[a] - grid.cellLo[a];
            std::uniform_real_distribution<double> inside(grid.cellLo[a] - 0.2 * extent, grid.cellHi[a] + 0.2 * extent);
            ray.origin[a] = inside(rng);
            ray.direction[a] = std::uniform_real_distribution<double>(-1, 1)(rng);
        }
        if (i % 11 == 0) ray.direction[i % 3] = (i % 22 == 0) ? -0.0 : 0.0;
        rays.push_back(ray);
    }
    return rays;
}

// Both hit kinds of a real grid: GPU vs CPU on camera and random rays, as a
// batch of rays (traceHits) and, with `primary`, the camera's rays made on
// the device (tracePrimary; then first hits only from those: every pipeline
// variant costs a compile of seconds on lavapipe). Returns the rays traced in
// all; `hits` gets the CPU's first hits among the distinct rays.
size_t compareOnGrid(const format::EncodedGrid& encoded, int width, int height, size_t randomCount, const std::string& walkLabel, size_t& hits,
                     bool primary) {
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded);
    const std::vector<Ray> rays = sceneRays(grid, width, height, randomCount, 99);
    const trace::DagTracer tracer(encoded.active.dag);
    gpu::VulkanTracer gpuTracer(*context(), grid);
    const std::vector<RayHit> wantFirst = cpuHits(tracer, rays);
    hits = 0;
    for (const RayHit& h : wantFirst) hits += h.hit;
    size_t traced = 0;
    const size_t pixels = size_t(width) * size_t(height);
    const std::span<const Ray> cameraRays(rays.data(), pixels);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(grid.indexToWorld), grid.cellLo, grid.cellHi, width, height);
    for (const bool floatWalk : {false, true}) {  // both arithmetics of the walk (VulkanTracer::setFloatWalk)
    gpuTracer.setFloatWalk(floatWalk);
    const std::string label = walkLabel + (floatWalk ? " (float walk)" : " (double walk)");
    if (primary) {
        EXPECT_EQ(countMismatches(gpuTracer.tracePrimary(camera), std::span<const RayHit>(wantFirst.data(), pixels), cameraRays,
                                  label + " primary rays"),
                  0u);
        traced += pixels;
    } else {
        EXPECT_EQ(countMismatches(gpuTracer.traceHits(rays, gpu::HitKind::FirstHit), wantFirst, rays, label + " first hit"), 0u);
        traced += rays.size();
    }
    if (grid.levelSet) {
        const std::vector<RayHit> surface = gpuTracer.traceHits(rays, gpu::HitKind::Surface);
        const std::vector<RayHit> wantSurface = cpuSurfaceHits(grid, tracer, rays);
        EXPECT_EQ(countMismatches(surface, wantSurface, rays, label + " zero crossing"), 0u);
        traced += rays.size();
        if (primary) {
            EXPECT_EQ(countMismatches(gpuTracer.tracePrimary(camera, gpu::HitKind::Surface),
                                      std::span<const RayHit>(wantSurface.data(), pixels), cameraRays, label + " primary zero crossing"),
                      0u);
            traced += pixels;
        }
    }
    }
    return traced;
}

} // namespace

TEST(VulkanTracer, AgreesWithTheCpuTracerOnRandomGridsWithTilesAndMirroredBricks) {
    VULKAN_OR_SKIP();
    std::mt19937_64 rng(17);
    size_t total = 0;
    for (int g = 0; g < 4; ++g) {
        const encoding::CompactDag dag = compactOf(randomTopology(rng, 6, g % 2 ? -24 : 8), g < 3);
        const trace::DagTracer tracer(dag);
        gpu::VulkanTracer gpuTracer(*context(), geometryOnly(dag));
        std::vector<Ray> rays(100000);
        for (size_t i = 0; i < rays.size(); ++i) {
            Ray& ray = rays[i];
            for (int a = 0; a < 3; ++a) {
                ray.origin[a] = std::uniform_real_distribution<double>(-40, 80)(rng);
                ray.direction[a] = std::uniform_real_distribution<double>(-1, 1)(rng);
            }
            if (i % 3 == 0)  // dyadic rays land exactly on faces, edges and corners
                for (int a = 0; a < 3; ++a) ray.origin[a] = dyadic(rng, -40, 80, 1), ray.direction[a] = dyadic(rng, -1, 1, 2);
            if (i % 7 == 0) ray.direction[i % 3] = (i % 14 == 0) ? -0.0 : 0.0;
            if (i % 13 == 0) ray.tMin = 5, ray.tMax = 60;
        }
        const std::vector<RayHit> want = cpuHits(tracer, rays);
        EXPECT_EQ(countMismatches(gpuTracer.traceHits(rays), want, rays, "random grid " + std::to_string(g)), 0u);
        gpuTracer.setFloatWalk(!gpuTracer.floatWalk());  // the other arithmetic of the walk, the same hits
        EXPECT_EQ(countMismatches(gpuTracer.traceHits(rays), want, rays, "random grid, other walk " + std::to_string(g)), 0u);
        // LOD cut-off: a node no larger than lodScale * t is a hit.
        trace::TraceOptions lod;
        lod.lodScale = 0.05;
        const trace::DagTracer lodTracer(dag, lod);
        const std::vector<Ray> some(rays.begin(), rays.begin() + 20000);
        EXPECT_EQ(countMismatches(gpuTracer.traceHits(some, gpu::HitKind::FirstHit, 0.05), cpuHits(lodTracer, some), some,
                                  "LOD random grid " + std::to_string(g)),
                  0u);
        total += rays.size() + some.size();
    }
    RecordProperty("rays", int(total));
}

TEST(VulkanTracer, AdversarialRaysRootsSpanning2To32AndTheUnitCubeAgreeWithTheExactReference) {
    VULKAN_OR_SKIP();
    std::mt19937_64 rng(11);
    const encoding::CompactDag dag = compactOf(randomTopology(rng, 3, 0));
    const trace::ExactRayReference reference(dag);
    gpu::VulkanTracer gpuTracer(*context(), geometryOnly(dag));
    const double zeros[2] = {0.0, -0.0};
    std::vector<Ray> rays;
    for (int i = 0; i < 6000; ++i) {
        Ray ray;
        for (int a = 0; a < 3; ++a) {
            const int64_t cell = int64_t(rng() % 34) - 5;
            const int pick = int(rng() % 3);
            ray.origin[a] = double(cell) + (pick == 0 ? 0.0 : pick == 1 ? 0.5 : 0.25);
        }
        const int axis = int(rng() % 3);
        const int pattern = int(rng() % 3);
        for (int a = 0; a < 3; ++a) {
            const double sign = (rng() & 1) ? 1.0 : -1.0;
            if (pattern == 0) ray.direction[a] = a == axis ? sign * double(1 + rng() % 3) : zeros[rng() & 1];
            else if (pattern == 1) ray.direction[a] = a == axis ? zeros[rng() & 1] : sign;
            else ray.direction[a] = sign * (rng() % 2 ? 1.0 : 0.5);
        }
        rays.push_back(ray);
    }
    for (int i = 0; i < 300; ++i) {  // zero direction: a point query at tMin
        Ray still;
        still.direction = {0.0, -0.0, 0.0};
        still.origin = {double(rng() % 24) + 0.5, double(rng() % 24) + 0.5, double(rng() % 24) + 0.5};
        rays.push_back(still);
    }
    std::vector<RayHit> want;
    size_t hits = 0;
    for (const Ray& ray : rays) {
        want.push_back(reference.trace(ray));
        hits += want.back().hit;
    }
    EXPECT_GT(hits, 600u);
    // The reference's t is exact; the tracers' is the rounded crossing time.
    for (const bool floatWalk : {false, true}) {
        gpuTracer.setFloatWalk(floatWalk);
        EXPECT_EQ(countMismatches(gpuTracer.traceHits(rays), want, rays, floatWalk ? "adversarial, float walk" : "adversarial", false), 0u);
    }

    // Non-finite rays miss; tMax stops a ray before the grid.
    std::vector<Ray> bad;
    for (double b : {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()})
        for (int a = 0; a < 6; ++a) {
            Ray ray;
            ray.origin = {1.5, 2.5, -3};
            ray.direction = {0.1, 0.2, 1};
            (a < 3 ? ray.origin : ray.direction)[a % 3] = b;
            bad.push_back(ray);
        }
    Ray bounded;
    bounded.origin = {4.5, 4.5, -100};
    bounded.direction = {0, 0, 1};
    bounded.tMax = 50;
    bad.push_back(bounded);
    for (const RayHit& h : gpuTracer.traceHits(bad)) EXPECT_FALSE(h.hit);

    // Roots spanning 2^24 and 2^32 voxels (the one pipeline is compiled once per process).
    {
    for (const int64_t far : {int64_t(1) << 23, int64_t(std::numeric_limits<int32_t>::max()) - 3}) {
        GridTopology topology;
        const int32_t hiCorner = int32_t(far & ~int64_t(3));
        const int32_t loCorner = int32_t(-(far + 1) & ~int64_t(3));
        topology.bricks.push_back({loCorner, loCorner, loCorner, 0x8000000000000001ull});
        topology.bricks.push_back({hiCorner, hiCorner, hiCorner, 0x8000000000000001ull});
        topology.bricks.push_back({0, 0, 0, 0xFFFFull});
        const encoding::CompactDag dag = compactOf(topology);
        ASSERT_GE(dag.log2Size, far > (1 << 24) ? 32 : 24);
        const trace::ExactRayReference reference(dag);
        gpu::VulkanTracer gpuTracer(*context(), geometryOnly(dag));
        std::vector<Ray> rays;
        const double c[3][3] = {{double(loCorner), double(loCorner), double(loCorner)},
                                {double(hiCorner + 3), double(hiCorner + 3), double(hiCorner + 3)},
                                {1.0, 1.0, 0.0}};
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a)
                for (double s : {1.0, -1.0}) {
                    Ray ray;
                    for (int b = 0; b < 3; ++b) ray.origin[b] = c[k][b] + 0.5, ray.direction[b] = 0.0;
                    ray.origin[a] = c[k][a] + 0.5 - s * 1000.0;
                    ray.direction[a] = s;
                    rays.push_back(ray);
                }
        Ray diagonal;
        for (int b = 0; b < 3; ++b) diagonal.origin[b] = double(loCorner) - 7.25, diagonal.direction[b] = 1.0;
        rays.push_back(diagonal);
        Ray back = diagonal;
        for (int b = 0; b < 3; ++b) back.origin[b] = double(hiCorner) + 9.75, back.direction[b] = -1.0;
        rays.push_back(back);
        std::vector<RayHit> want;
        for (const Ray& ray : rays) {
            want.push_back(reference.trace(ray));
            ASSERT_TRUE(want.back().hit);
        }
        for (const bool floatWalk : {false, true}) {
            gpuTracer.setFloatWalk(floatWalk);
            const std::vector<RayHit> got = gpuTracer.traceHits(rays);
            EXPECT_EQ(countMismatches(got, want, rays, "root 2^" + std::to_string(dag.log2Size) + (floatWalk ? " float walk" : ""), false), 0u);
            for (const RayHit& h : got) EXPECT_LT(h.steps, 64u * dag.log2Size);
        }
    }
    // Origin (0.49, 0.49, -1), direction (0, 0, 2) into a one-voxel grid: voxel (0,0,0) at t = 0.5 through -z.
    GridTopology one;
    one.bricks.push_back({0, 0, 0, 1});
    const encoding::CompactDag dag = compactOf(one);
    gpu::VulkanTracer gpuTracer(*context(), geometryOnly(dag));
    std::vector<Ray> rays(3);
    rays[0].origin = {0.49, 0.49, -1.0};
    rays[1].origin = {0.99999999, 0.0, -1.0};
    rays[2].origin = {1.0, 0.0, -1.0};
    for (Ray& r : rays) r.direction = {0.0, 0.0, 2.0};
    const std::vector<RayHit> got = gpuTracer.traceHits(rays);
    ASSERT_TRUE(got[0].hit);
    EXPECT_EQ(got[0].voxel, (std::array<int64_t, 3>{0, 0, 0}));
    EXPECT_EQ(got[0].t, 0.5);
    EXPECT_EQ(got[0].faceAxis, 2);
    EXPECT_EQ(got[0].faceSign, -1);
    EXPECT_TRUE(got[1].hit);
    EXPECT_FALSE(got[2].hit);
    }
}


TEST(VulkanTracer, AgreesWithTheCpuTracerOnTheGeneratedSamples) {
    VULKAN_OR_SKIP();
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_vk_samples_" + std::to_string(::getpid()));
    fs::remove_all(dir);  // a finished process with the same PID may have left it
    fs::create_directories(dir);
    ASSERT_EQ(std::system((std::string(VDBDAG_SAMPLES_TOOL) + " " + dir.string() + " > /dev/null").c_str()), 0);
    size_t total = 0, grids = 0, hits = 0, distinct = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        if (e.path().extension() != ".vdb") continue;
        const auto imported = bridge::importVdb(e.path().string());
        for (const GridRecord& record : imported.volume.grids) {
            const format::EncodedGrid encoded = pipeline::encodeGrid(record);
            if (encoded.active.dag.empty()) continue;
            size_t gridHits = 0;
            total += compareOnGrid(encoded, 128, 96, 10000, e.path().filename().string() + ":" + record.name, gridHits, false);
            hits += gridHits;
            distinct += 128 * 96 + 10000;
            ++grids;
        }
    }
    fs::remove_all(dir);
    EXPECT_GE(grids, 6u);
    EXPECT_GT(hits, distinct / 10) << "the rays should hit often enough to mean something";
    RecordProperty("rays", int(total));
}

TEST(VulkanTracer, AgreesWithTheCpuTracerOnTheSharedLevelSets) {
    VULKAN_OR_SKIP();
    const fs::path data = fs::path(VDBDAG_SHARED_DATA) / "levelsets";
    if (!fs::exists(data / "bunny_d512_ls.vdb")) GTEST_SKIP() << "no " << data;
    size_t total = 0;
    for (const char* name : {"bunny_d512_ls.vdb", "armadillo_d512_ls.vdb"}) {
        if (!fs::exists(data / name)) continue;
        const auto imported = bridge::importVdb((data / name).string());
        const format::EncodedGrid encoded = pipeline::encodeGrid(imported.volume.grids.at(0));
        ASSERT_TRUE(trace::makeRenderGrid(encoded).levelSet);
        size_t hits = 0;
        total += compareOnGrid(encoded, 256, 192, 40000, name, hits, true);
        EXPECT_GT(hits, size_t(256 * 192 + 40000) / 10) << name << ": the rays should hit often enough to mean something";
    }
    RecordProperty("rays", int(total));
}

namespace {

// Float components of two renders' normals that differ (bit for bit).
size_t differingNormals(const trace::Image& a, const trace::Image& b) {
    size_t n = 0;
    for (size_t i = 0; i < a.normal.size(); ++i) n += a.normal[i] != b.normal[i];
    return n;
}

// The largest angle (degrees) between the normals of two renders of the same
// scene, over the pixels both cover.
double maxNormalAngle(const trace::Image& a, const trace::Image& b) {
    double worst = 0;
    for (size_t i = 0; i < a.alpha.size(); ++i) {
        if (!(a.alpha[i] > 0) || !(b.alpha[i] > 0)) continue;
        const std::array<float, 3> na{a.normal[3 * i], a.normal[3 * i + 1], a.normal[3 * i + 2]};
        const std::array<float, 3> nb{b.normal[3 * i], b.normal[3 * i + 1], b.normal[3 * i + 2]};
        worst = std::max(worst, attributes::angleDegrees(na, nb));
    }
    return worst;
}

} // namespace

TEST(VulkanTracer, RendersALevelSetSphereLikeTheCpuRenderer) {
    VULKAN_OR_SKIP();
    openvdb::initialize();
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.1f, -0.2f, 0.3f), 1.0f / 40.0f, 3.0f);
    sphere->setName("sphere");
    const format::EncodedGrid encoded = encodeVdbGrid(sphere, "vdbdag_vk_sphere");
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded);
    ASSERT_TRUE(grid.levelSet);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(grid.indexToWorld), grid.cellLo, grid.cellHi, 160, 120);
    gpu::VulkanTracer gpuTracer(*context(), grid);
    {  // with shadow rays (shading without them is the same code minus the shadow ray; one pipeline compile less)
        trace::RenderOptions options;
        options.shadows = true;
        trace::RenderStats cpuStats, gpuStats;
        const trace::Image cpu = trace::renderCpu(grid, camera, options, &cpuStats);
        const trace::Image gpu = gpuTracer.render(grid, camera, options, gpuStats);
        expectSameImage(gpu, cpu, 1e-6, "sphere with shadows");
        EXPECT_EQ(gpuStats.primaryRays, cpuStats.primaryRays);
        EXPECT_EQ(gpuStats.secondaryRays, cpuStats.secondaryRays);
        EXPECT_GT(gpuStats.secondaryRays, 1000u);
    }
    trace::RenderOptions lod;
    lod.shadows = true;
    lod.lodPixels = 4;
    trace::RenderStats stats;
    expectSameImage(gpuTracer.render(grid, camera, lod, stats), trace::renderCpu(grid, camera, lod), 1e-6, "sphere LOD 4 px");
    gpuTracer.setFloatWalk(!gpuTracer.floatWalk());  // the other arithmetic of the walk: the same image
    expectSameImage(gpuTracer.render(grid, camera, lod, stats), trace::renderCpu(grid, camera, lod), 1e-6, "sphere LOD 4 px, other walk");
    // Every array (DAG and palette sections) split into 4 KiB chunks: the
    // path of arrays beyond one allocation.
    trace::RenderOptions shadows;
    shadows.shadows = true;
    gpu::VulkanTracer chunked(*context(), grid, 12);
    expectSameImage(chunked.render(grid, camera, shadows, stats), trace::renderCpu(grid, camera, shadows), 1e-6, "sphere, chunked arrays");
}

TEST(VulkanTracer, RendersAFogSphereLikeTheCpuRenderer) {
    VULKAN_OR_SKIP();
    openvdb::initialize();
    auto fog = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.0f), 1.0f / 24.0f, 3.0f);
    openvdb::tools::sdfToFogVolume(*fog);
    fog->setName("density");
    const format::EncodedGrid encoded = encodeVdbGrid(fog, "vdbdag_vk_fog");
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded);
    ASSERT_TRUE(grid.fog);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(grid.indexToWorld), grid.cellLo, grid.cellHi, 120, 90);
    gpu::VulkanTracer gpuTracer(*context(), grid);
    trace::RenderOptions options;
    options.densityScale = 0.3;
    trace::RenderStats stats;
    // exp() differs in the last bits (a polynomial on the GPU): colours agree to ~1e-6.
    const trace::Image cpu = trace::renderCpu(grid, camera, options);
    expectSameImage(gpuTracer.render(grid, camera, options, stats), cpu, 1e-5, "fog sphere");
    gpuTracer.setFloatWalk(!gpuTracer.floatWalk());  // the other arithmetic of the walk: the same image
    expectSameImage(gpuTracer.render(grid, camera, options, stats), cpu, 1e-5, "fog sphere, other walk");
}

// `encode --normals K` on a level set: the GPU decodes the stored ONV codes
// (palette lookup, octahedral unfold) bit for bit as the CPU does and shades
// with them, gradient-sourced so never flipped.
TEST(VulkanTracer, ShadesWithStoredOnvNormalsLikeTheCpuRenderer) {
    VULKAN_OR_SKIP();
    openvdb::initialize();
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.1f, -0.2f, 0.3f), 1.0f / 40.0f, 3.0f);
    sphere->setName("sphere");
    bridge::ImportOptions io;
    io.normals = true;
    const auto imported = importVdbGrids({sphere}, "vdbdag_vk_onv_sphere", io);
    const GridRecord& record = imported.volume.grids.at(0);
    ASSERT_TRUE(record.normals.has_value());
    trace::RenderOptions options;
    options.shadows = true;
    trace::RenderStats stats;

    // The same grid without stored normals: shaded by the level-set gradient.
    const format::EncodedGrid plainEncoded = pipeline::encodeGrid(record);
    ASSERT_FALSE(plainEncoded.normals.has_value());
    const trace::RenderGrid plainGrid = trace::makeRenderGrid(plainEncoded);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(plainGrid.indexToWorld), plainGrid.cellLo, plainGrid.cellHi, 160, 120);
    gpu::VulkanTracer plainTracer(*context(), plainGrid);
    const trace::Image plain = plainTracer.render(plainGrid, camera, options, stats);

    for (unsigned bits : {10u, 32u}) {
        const std::string label = "sphere with " + std::to_string(bits) + "-bit ONV normals";
        pipeline::EncodeOptions eo;
        eo.normalBits = bits;
        const format::EncodedGrid encoded = pipeline::encodeGrid(record, eo);
        ASSERT_TRUE(encoded.normals.has_value());
        EXPECT_EQ(encoded.normals->report.source, attributes::NormalReport::Source::Gradient);
        const trace::RenderGrid grid = trace::makeRenderGrid(encoded);
        ASSERT_EQ(grid.normals, &*encoded.normals);
        gpu::VulkanTracer gpuTracer(*context(), grid);
        const trace::Image gpu = gpuTracer.render(grid, camera, options, stats);
        const trace::Image cpu = trace::renderCpu(grid, camera, options);
        expectSameImage(gpu, cpu, 1e-6, label);
        EXPECT_EQ(differingNormals(gpu, cpu), 0u) << label << ": the decoded normals are not bit-identical";
        const double angle = maxNormalAngle(gpu, plain);
        if (bits == 10) EXPECT_GT(angle, 0.5) << label << ": the stored normals are not used";
        else EXPECT_LT(angle, 5.0) << label << ": far from the level set's own gradient";
    }
}

// Normals from a normal grid (`--normal-grid`) have no orientation: like face
// normals they are flipped towards the viewer. Inward vectors here, so every
// visible one is flipped; on its own thin shell, with 16-bit codes.
TEST(VulkanTracer, ShadesWithNormalGridOnvNormalsFlippedLikeTheCpuRenderer) {
    VULKAN_OR_SKIP();
    openvdb::initialize();
    const openvdb::Vec3f centre(0.1f, -0.2f, 0.3f);
    auto ls = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, centre, 1.0f / 24.0f, 3.0f);
    ls->setName("sphere");
    auto inward = openvdb::Vec3SGrid::create(openvdb::Vec3s(0));
    inward->setName("N");
    inward->setTransform(ls->transform().copy());
    auto acc = inward->getAccessor();
    for (auto it = ls->cbeginValueOn(); it; ++it) {
        if (std::fabs(*it) > 0.6f) continue;  // a thin shell only
        const openvdb::Vec3d d = ls->indexToWorld(it.getCoord()) - openvdb::Vec3d(centre);
        acc.setValue(it.getCoord(), openvdb::Vec3s(d * -3.0));
    }
    bridge::ImportOptions io;
    io.normals = true;
    io.normalGrid = "N";
    const auto imported = importVdbGrids({inward}, "vdbdag_vk_onv_normal_grid", io);
    pipeline::EncodeOptions eo;
    eo.normalBits = 16;
    const format::EncodedGrid encoded = pipeline::encodeGrid(imported.volume.grids.at(0), eo);
    ASSERT_TRUE(encoded.normals.has_value());
    EXPECT_EQ(encoded.normals->report.source, attributes::NormalReport::Source::NormalGrid);
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded);
    ASSERT_NE(grid.normals, nullptr);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(grid.indexToWorld), grid.cellLo, grid.cellHi, 96, 72);
    gpu::VulkanTracer gpuTracer(*context(), grid);
    trace::RenderOptions options;
    trace::RenderStats stats;
    const trace::Image gpu = gpuTracer.render(grid, camera, options, stats);
    const trace::Image cpu = trace::renderCpu(grid, camera, options);
    expectSameImage(gpu, cpu, 1e-6, "shell with normal-grid ONV normals");
    EXPECT_EQ(differingNormals(gpu, cpu), 0u);
    // Flipped: every visible normal faces the viewer, i.e. points outwards
    // here, against the stored (inward) vectors.
    size_t facing = 0, covered = 0;
    for (int py = 0; py < camera.height; ++py)
        for (int px = 0; px < camera.width; ++px) {
            const size_t i = size_t(py) * camera.width + px;
            if (!(gpu.alpha[i] > 0)) continue;
            ++covered;
            glm::dvec3 eye, dir;
            camera.pixelRay(px, py, eye, dir);
            facing += dir[0] * gpu.normal[3 * i] + dir[1] * gpu.normal[3 * i + 1] + dir[2] * gpu.normal[3 * i + 2] <= 1e-6;  // float normals at grazing pixels
        }
    EXPECT_GT(covered, 100u);
    EXPECT_EQ(facing, covered);
}

// The walk in floats (VulkanTracer::setFloatWalk; WALK_FP32 in
// trace_walk.glsl) against the walk in doubles and the CPU tracer: the same
// hits, t bit for bit, on rays built to fall near ties (crossings a float
// cannot tell apart and a double can: directions 2^-10..2^-40 off a
// diagonal, from lattice points, near and 1000 voxels away), and on a
// level set's camera rays with almost every step decided in floats.
TEST(VulkanTracer, TheFloatWalkReturnsTheDoubleWalksHitsAndDecidesMostStepsInFloats) {
    VULKAN_OR_SKIP();
    std::mt19937_64 rng(23);
    const encoding::CompactDag dag = compactOf(randomTopology(rng, 6, 8), true);
    const trace::DagTracer tracer(dag);
    gpu::VulkanTracer gpuTracer(*context(), geometryOnly(dag));
    EXPECT_EQ(gpuTracer.floatWalk(), gpuTracer.deviceInfo().type != "CPU") << "the float walk is the default on GPUs";
    std::vector<Ray> rays(60000);
    for (size_t i = 0; i < rays.size(); ++i) {
        Ray& ray = rays[i];
        for (int a = 0; a < 3; ++a) {
            const double sign = (rng() & 1) ? 1.0 : -1.0;
            const double off = std::ldexp(double(int(rng() % 3) - 1), -int(10 + rng() % 31));
            ray.direction[a] = i % 4 == 3 ? std::uniform_real_distribution<double>(-1, 1)(rng) : sign * (1.0 + off);
            ray.origin[a] = double(int64_t(rng() % 90) - 25) + (i % 2 ? 0.5 : 0.0);
        }
        if (i % 5 == 0)
            for (int a = 0; a < 3; ++a) ray.origin[a] -= 1000.0 * ray.direction[a];
        if (i % 11 == 0) ray.direction[i % 3] = 0.0;
    }
    const std::vector<RayHit> want = cpuHits(tracer, rays);
    gpuTracer.setFloatWalk(false);
    const std::vector<RayHit> wide = gpuTracer.traceHits(rays);
    gpuTracer.setFloatWalk(true);
    const std::vector<RayHit> narrow = gpuTracer.traceHits(rays);
    EXPECT_EQ(countMismatches(wide, want, rays, "double walk"), 0u);
    EXPECT_EQ(countMismatches(narrow, want, rays, "float walk"), 0u);
    size_t hits = 0, wideOnly = 0, fellBack = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        hits += want[i].hit;
        wideOnly += wide[i].hit && std::min(wide[i].steps, 127u) != wide[i].wideSteps;
        fellBack += narrow[i].wideSteps > 0;
    }
    EXPECT_GT(hits, rays.size() / 10);
    EXPECT_EQ(wideOnly, 0u) << "without the float walk every step runs in doubles";
    std::printf("float walk, near ties: %zu of %zu rays took a step in doubles\n", fellBack, rays.size());
    EXPECT_GT(fellBack, 100u) << "the near ties should need the doubles";

    // Rays from lattice points with tMin < 0 (first hits start there, as
    // DagTracer::trace does): hits at t = 0, where the crossing on an axis
    // moving down is -0.0 and on one moving up +0.0, and a tie of the two
    // may come from either axis. Both tracers report +0.0, bit for bit.
    std::vector<Ray> lattice(20000);
    for (Ray& ray : lattice) {
        for (int a = 0; a < 3; ++a) {
            ray.origin[a] = double(rng() % 30);
            const double m[4] = {1.0, 0.5, 0.3, 0.0};
            ray.direction[a] = ((rng() & 1) ? 1.0 : -1.0) * m[rng() % 4];
        }
        ray.tMin = -1.0;
    }
    const std::vector<RayHit> latticeWant = cpuHits(tracer, lattice);
    gpuTracer.setFloatWalk(false);
    const std::vector<RayHit> latticeWide = gpuTracer.traceHits(lattice);
    EXPECT_EQ(countMismatches(latticeWide, latticeWant, lattice, "lattice rays, double walk"), 0u);
    gpuTracer.setFloatWalk(true);
    const std::vector<RayHit> latticeGot = gpuTracer.traceHits(lattice);
    EXPECT_EQ(countMismatches(latticeGot, latticeWant, lattice, "lattice rays, float walk"), 0u);
    size_t atZero = 0, signs = 0;
    for (size_t i = 0; i < lattice.size(); ++i)
        if (latticeWant[i].hit && latticeWant[i].t == 0) {
            ++atZero;
            signs += std::signbit(latticeWant[i].t) + std::signbit(latticeGot[i].t) + std::signbit(latticeWide[i].t);
        }
    EXPECT_GT(atZero, 100u);
    EXPECT_EQ(signs, 0u) << "hits at t = -0.0 of " << atZero << " at t = 0";

    // A level set's camera rays, first hit and zero crossing.
    openvdb::initialize();
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.1f, -0.2f, 0.3f), 1.0f / 60.0f, 3.0f);
    sphere->setName("sphere");
    const format::EncodedGrid encoded = encodeVdbGrid(sphere, "vdbdag_vk_float_walk");
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded);
    const std::vector<Ray> camera = sceneRays(grid, 160, 120, 0, 5);
    const trace::DagTracer sphereTracer(encoded.active.dag);
    gpu::VulkanTracer sphereGpu(*context(), grid);
    sphereGpu.setFloatWalk(true);
    for (const gpu::HitKind kind : {gpu::HitKind::FirstHit, gpu::HitKind::Surface}) {
        const std::vector<RayHit> got = sphereGpu.traceHits(camera, kind);
        const std::vector<RayHit> expect = kind == gpu::HitKind::FirstHit ? cpuHits(sphereTracer, camera) : cpuSurfaceHits(grid, sphereTracer, camera);
        EXPECT_EQ(countMismatches(got, expect, camera, "sphere camera rays"), 0u);
        uint64_t steps = 0, wideSteps = 0;
        size_t sphereHits = 0;
        for (const RayHit& h : got) {
            steps += h.steps;
            wideSteps += h.wideSteps;
            sphereHits += h.hit;
        }
        EXPECT_GT(sphereHits, camera.size() / 10);
        std::printf("float walk, sphere %s: %llu of %llu steps in doubles\n", kind == gpu::HitKind::FirstHit ? "first hit" : "zero crossing",
                    (unsigned long long)wideSteps, (unsigned long long)steps);
        EXPECT_LT(double(wideSteps), 0.01 * double(steps)) << wideSteps << " of " << steps << " steps in doubles";
        RecordProperty(kind == gpu::HitKind::FirstHit ? "first_hit_steps_in_doubles_per_mille" : "surface_steps_in_doubles_per_mille",
                       int(1000.0 * double(wideSteps) / double(std::max<uint64_t>(steps, 1))));
    }
}
