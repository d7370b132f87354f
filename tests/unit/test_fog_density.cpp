// The default density scale of fog renders (src/trace/FogDensity.h) against
// a closed form, and what it does to a fog's picture (issue 42 #2: a fog
// rendered as a flat white cut-out at the fixed scale).
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <utility>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include "tests/unit/BuildPaths.h"
#include "src/pipeline/GridCodec.h"
#include "src/trace/Camera.h"
#include "src/trace/CpuRenderer.h"
#include "src/trace/FogDensity.h"
#include "src/trace/RenderGrid.h"
#include "vdb_bridge/VdbImport.h"

namespace fs = std::filesystem;
using namespace vdbdag;

namespace {

GridRecord importGrid(openvdb::FloatGrid::Ptr grid, const std::string& name) {
    openvdb::initialize();
    grid->setName(name);
    const fs::path path = fs::temp_directory_path() / ("vdbdag_fog_" + name + "_" + std::to_string(::getpid()) + ".vdb");
    {
        openvdb::io::File file(path.string());
        file.write({grid});
    }
    GridRecord record = bridge::importVdb(path.string(), {}).volume.grids.at(0);
    fs::remove(path);
    return record;
}

// Of the pixels a fog covers (alpha > 0.01), the fraction that is opaque
// (alpha >= 0.99): there the picture is the fog's flat emission colour.
double saturatedFraction(const trace::Image& image) {
    size_t covered = 0, opaque = 0;
    for (const float a : image.alpha) {
        if (a <= 0.01f) continue;
        ++covered;
        opaque += a >= 0.99f;
    }
    return covered ? double(opaque) / double(covered) : 0.0;
}

// The opaque fraction of a fog's default view (size x size pixels) at the
// old fixed scale 0.08 and at the default scale, printed under `label`.
std::pair<double, double> opaqueAtFixedAndDefault(const trace::RenderGrid& grid, int size, const char* label) {
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(grid.indexToWorld), grid.cellLo, grid.cellHi, size, size);
    trace::RenderOptions fixed, automatic;
    fixed.densityScale = 0.08;
    automatic.densityScale = trace::autoDensityScale(grid, camera, 0.08);
    const double before = saturatedFraction(trace::renderCpu(grid, camera, fixed)), after = saturatedFraction(trace::renderCpu(grid, camera, automatic));
    std::printf("%s: opaque fraction of covered pixels %.3f at 0.08, %.3f at the default %.5f\n", label, before, after, automatic.densityScale);
    return {before, after};
}

} // namespace

// A uniform cube of 32^3 voxels (density 2, voxel 0.5) seen face-on from
// far away through a narrow field: every sampled ray crosses 32 voxel
// lengths of the largest density, so the optical depth at scale s is 32 s
// and the median is 1 at s = 1/32.
TEST(FogDensity, AUniformCubeSeenFaceOnGetsOneOverItsThickness) {
    openvdb::initialize();
    auto cube = openvdb::FloatGrid::create(0.0f);
    cube->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
    cube->setGridClass(openvdb::GRID_FOG_VOLUME);
    cube->denseFill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(31)), 2.0f, true);
    const format::EncodedGrid encoded = pipeline::encodeGrid(importGrid(cube, "cube"));
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded);
    ASSERT_TRUE(grid.fog);
    trace::Camera camera;
    camera.width = camera.height = 32;
    camera.eye = {8.0, 8.0, -1000.0};  // world centre of the cube: (16 voxels) x 0.5
    camera.target = {8.0, 8.0, 8.0};
    camera.up = {0.0, 1.0, 0.0};
    camera.fovDegrees = 0.5;  // a 8.7-unit-wide view at 1000 units: within the cube's 16-unit face
    EXPECT_NEAR(trace::autoDensityScale(grid, camera, 0.08), 1.0 / 32.0, 1e-3);
    // No fog, no change: the fallback.
    EXPECT_EQ(trace::autoDensityScale(trace::makeRenderGrid(encoded, trace::Shading::Values), camera, 0.08), 0.08);
}

// A dense sphere fog 200 voxels across: at the old fixed scale (0.08 per
// voxel length) most covered pixels are opaque, a white disc; at the
// default scale fewer than half are.
TEST(FogDensity, ADenseFogIsTranslucentAtTheDefaultScale) {
    openvdb::initialize();
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(100.0f, openvdb::Vec3f(0.0f), 1.0f, 3.0f);
    openvdb::tools::sdfToFogVolume(*sphere);
    const format::EncodedGrid encoded = pipeline::encodeGrid(importGrid(sphere, "ball"));
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded);
    ASSERT_TRUE(grid.fog);
    const auto [before, after] = opaqueAtFixedAndDefault(grid, 96, "sphere fog 200 voxels across");
    EXPECT_GT(before, 0.5);
    EXPECT_LT(after, 0.5);
}

// The bunny fog of ../shared/data (the picture the issue looked at): its
// default render is translucent where the fixed scale painted it white.
TEST(FogDensity, TheBunnyFogIsTranslucentAtTheDefaultScale) {
    const fs::path path = fs::path(VDBDAG_SHARED_DATA) / "levelsets" / "bunny_d512_fog.vdb";
    if (!fs::exists(path)) GTEST_SKIP() << "needs ../shared/data";
    const format::EncodedGrid encoded = pipeline::encodeGrid(bridge::importVdb(path.string(), {}).volume.grids.at(0));
    const trace::RenderGrid grid = trace::makeRenderGrid(encoded);
    ASSERT_TRUE(grid.fog);
    const auto [before, after] = opaqueAtFixedAndDefault(grid, 128, "bunny fog");
    EXPECT_GT(before, after);
    EXPECT_LT(after, 0.5);
}
