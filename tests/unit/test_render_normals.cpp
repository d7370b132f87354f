// The CPU renderer's shading normals against a closed form: a level-set
// sphere encoded with ONV normals (`encode --normals K`). Every covered
// pixel's normal must be close to the sphere's radial direction at the hit
// point, the stored normals must be the ones used (a 10-bit render differs
// from a render without normals), and a finer ONV must come closer to the
// exact gradient shading than a coarser one.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "tests/unit/BuildPaths.h"
#include "src/pipeline/GridCodec.h"
#include "src/trace/Camera.h"
#include "src/trace/CpuRenderer.h"
#include "src/trace/RenderGrid.h"
#include "vdb_bridge/VdbImport.h"

namespace fs = std::filesystem;
using namespace vdbdag;

namespace {

constexpr double kRadius = 1.0, kVoxel = 1.0 / 40.0;

// The sphere's record with its exact gradient normals (import with normals),
// under a transform that also rotates (30 degrees about z, then 36 about x), so that
// index-space and world-space normals differ; `centre` gets the world centre.
GridRecord sphereWithNormals(glm::dvec3& centre) {
    openvdb::initialize();
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(float(kRadius), openvdb::Vec3f(0.1f, -0.2f, 0.3f), float(kVoxel), 3.0f);
    sphere->setName("sphere");
    const openvdb::Vec3d centreIndex = sphere->worldToIndex(openvdb::Vec3d(0.1, -0.2, 0.3));
    sphere->transform().postRotate(M_PI / 6, openvdb::math::Z_AXIS);
    sphere->transform().postRotate(M_PI / 5, openvdb::math::X_AXIS);
    const openvdb::Vec3d c = sphere->indexToWorld(centreIndex);
    centre = glm::dvec3(c.x(), c.y(), c.z());
    const fs::path path = fs::temp_directory_path() / ("vdbdag_render_normals_" + std::to_string(::getpid()) + ".vdb");
    {
        openvdb::io::File file(path.string());
        file.write({sphere});
    }
    bridge::ImportOptions options;
    options.normals = true;
    GridRecord record = bridge::importVdb(path.string(), options).volume.grids.at(0);
    fs::remove(path);
    return record;
}

double angleDegrees(const glm::dvec3& a, const glm::dvec3& b) {
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * 180.0 / M_PI;
}

struct NormalStats {
    size_t covered = 0;
    double maxToSphere = 0, meanToSphere = 0;  // degrees, against the radial direction at the hit point
};

NormalStats compareWithSphere(const trace::Image& image, const trace::Camera& camera, const glm::dvec3& centre) {
    NormalStats s;
    for (int py = 0; py < camera.height; ++py)
        for (int px = 0; px < camera.width; ++px) {
            const size_t i = size_t(py) * camera.width + px;
            if (!(image.alpha[i] > 0)) continue;
            glm::dvec3 eye, dir;
            camera.pixelRay(px, py, eye, dir);
            const glm::dvec3 hit = eye + double(image.depth[i]) * dir;  // depth: t along the world ray
            const glm::dvec3 n(image.normal[3 * i], image.normal[3 * i + 1], image.normal[3 * i + 2]);
            const double angle = angleDegrees(n, hit - centre);
            ++s.covered;
            s.maxToSphere = std::max(s.maxToSphere, angle);
            s.meanToSphere += angle;
        }
    if (s.covered) s.meanToSphere /= double(s.covered);
    return s;
}

double maxNormalDifference(const trace::Image& a, const trace::Image& b) {
    double worst = 0;
    for (size_t i = 0; i < a.alpha.size(); ++i) {
        if (!(a.alpha[i] > 0) || !(b.alpha[i] > 0)) continue;
        const glm::dvec3 na(a.normal[3 * i], a.normal[3 * i + 1], a.normal[3 * i + 2]), nb(b.normal[3 * i], b.normal[3 * i + 1], b.normal[3 * i + 2]);
        worst = std::max(worst, angleDegrees(na, nb));
    }
    return worst;
}

} // namespace

TEST(RenderNormals, StoredOnvNormalsShadeTheSphereCloseToItsRadialDirection) {
    glm::dvec3 centre;
    const GridRecord record = sphereWithNormals(centre);
    ASSERT_TRUE(record.normals.has_value());
    pipeline::EncodeOptions plain, coarse, fine;
    coarse.normalBits = 10;
    fine.normalBits = 32;
    const format::EncodedGrid none = pipeline::encodeGrid(record, plain), onv10 = pipeline::encodeGrid(record, coarse),
                              onv32 = pipeline::encodeGrid(record, fine);
    ASSERT_TRUE(onv10.normals && onv32.normals);
    ASSERT_FALSE(none.normals);

    const trace::RenderGrid gridNone = trace::makeRenderGrid(none), grid10 = trace::makeRenderGrid(onv10), grid32 = trace::makeRenderGrid(onv32);
    ASSERT_EQ(grid10.normals, &*onv10.normals);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(gridNone.indexToWorld), gridNone.cellLo, gridNone.cellHi, 120, 90);
    const trace::Image imageNone = trace::renderCpu(gridNone, camera, {}), image10 = trace::renderCpu(grid10, camera, {}),
                       image32 = trace::renderCpu(grid32, camera, {});

    // Hit points lie on voxel faces, up to about one voxel off the zero
    // surface: within 2 degrees of the radial direction at radius 40 voxels,
    // plus the k-bit ONV's closed-form bound 0.95 * 2^((16 - k) / 2) degrees
    // (tests/unit/test_colour_normal_codecs.cpp).
    const struct { const trace::Image* image; const char* label; double onvBound; } cases[] = {
        {&imageNone, "no normals", 0.0}, {&image10, "ONV 10", 0.95 * 8.0}, {&image32, "ONV 32", 0.95 / 256.0}};
    for (const auto& c : cases) {
        const NormalStats s = compareWithSphere(*c.image, camera, centre);
        EXPECT_GT(s.covered, size_t(400)) << c.label;
        EXPECT_LT(s.maxToSphere, 2.0 + c.onvBound) << c.label;
        EXPECT_LT(s.meanToSphere, 1.0 + c.onvBound / 2) << c.label;
        RecordProperty(std::string("mean_deg_to_sphere_") + c.label, std::to_string(s.meanToSphere));
    }
    // The stored normals are used: 10-bit ONVs (up to ~5 degrees off) change
    // the normals; 32-bit ones stay within 0.05 degrees of the exact
    // gradient shading, closer than the 10-bit ones.
    const double diff10 = maxNormalDifference(image10, imageNone), diff32 = maxNormalDifference(image32, imageNone);
    EXPECT_GT(diff10, 0.5);
    EXPECT_LT(diff32, diff10);
    RecordProperty("max_normal_diff_onv10_deg", std::to_string(diff10));
    RecordProperty("max_normal_diff_onv32_deg", std::to_string(diff32));
}

namespace {

// Surface pixels whose brightness differs from the mean of their four
// neighbours by more than 5% of full scale: silhouettes and shadow edges
// (curves, O(perimeter)) and speckles (O(area)).
size_t noisyPixels(const trace::Image& image, size_t* surface) {
    size_t noisy = 0;
    *surface = 0;
    auto lum = [&](int x, int y) {
        const size_t p = 3 * (size_t(y) * image.width + x);
        return (image.rgb[p] + image.rgb[p + 1] + image.rgb[p + 2]) / 3.0;
    };
    for (int y = 1; y + 1 < image.height; ++y)
        for (int x = 1; x + 1 < image.width; ++x) {
            if (image.alpha[size_t(y) * image.width + x] == 0) continue;
            ++*surface;
            const double mean = (lum(x - 1, y) + lum(x + 1, y) + lum(x, y - 1) + lum(x, y + 1)) / 4;
            if (std::abs(lum(x, y) - mean) > 0.05) ++noisy;
        }
    return noisy;
}

} // namespace

// Shadow rays of a level set start off its surface (Shading.h): the narrow
// band's staircase no longer shadows the smooth surface in stripes. A lit
// torus (the demo's sample) gains a shadow edge, not a field of speckles:
// at most 1% of its surface pixels more are noisy than without shadows.
TEST(RenderNormals, LevelSetShadowsAddNoSpeckles) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("vdbdag_speckles_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    ASSERT_EQ(std::system((std::string(VDBDAG_SAMPLES_TOOL) + " " + dir.string() + " > /dev/null").c_str()), 0);
    const bridge::ImportResult imported = bridge::importVdb((dir / "torus_ls.vdb").string());
    const format::SsvdagScene scene = pipeline::encodeVolume(imported.volume);
    const trace::RenderGrid grid = trace::makeRenderGrid(scene.grids[0]);
    ASSERT_TRUE(grid.levelSet);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(grid.indexToWorld), grid.cellLo, grid.cellHi, 512, 384);
    trace::RenderOptions lit, shadowed;
    shadowed.shadows = true;
    trace::RenderStats stats;
    const trace::Image plain = trace::renderCpu(grid, camera, lit), withShadows = trace::renderCpu(grid, camera, shadowed, &stats);
    ASSERT_GT(stats.secondaryRays, 1000u);
    size_t surface = 0, surfaceShadowed = 0;
    const size_t before = noisyPixels(plain, &surface), after = noisyPixels(withShadows, &surfaceShadowed);
    ASSERT_GT(surface, 10000u);
    EXPECT_LE(after, before + surface / 100) << after << " noisy pixels with shadows, " << before << " without, of " << surface;
    std::filesystem::remove_all(dir);
}
