// The Vulkan tracer's shadings beyond surfaces and fog (--shading mip,
// slice, labels, iso, volume) against the CPU renderer, on a real device
// (lavapipe here): the GPU walks the rays (every occupied box, as the CPU's
// segment walks) and the images are the CPU's bit for bit - the maxima,
// slice values and hits come back to the host, which windows or shades them
// with the CPU's own functions - except volume rendering, done whole in the
// shader (colours within 1e-6). Every test skips cleanly without a device.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include "gpu/VulkanTracer.h"
#include "src/trace/CpuRenderer.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/TransferFunction.h"
#include "tests/unit/VulkanTestSupport.h"

using namespace vdbdag;
using vdbdag::testing::context;
using vdbdag::testing::encodeVdbGrid;
using vdbdag::testing::expectSameImage;

// --shading mip: each pixel's largest value along its ray, through the
// window chosen from the maxima; the GPU walks every occupied box as the CPU
// does and its maxima are the same doubles, so the images are identical.
// --shading slice: each pixel's voxel on a plane, the same way.
TEST(VulkanTracer, MaximumIntensityProjectionAndSliceEqualTheCpuRenderer) {
    VULKAN_OR_SKIP();
    openvdb::initialize();
    auto fog = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.0f, openvdb::Vec3f(0.0f), 1.0f / 24.0f, 3.0f);
    openvdb::tools::sdfToFogVolume(*fog);
    fog->setName("density");
    // An int32 block of noise with a bright core: a scan's integers.
    auto scan = openvdb::Int32Grid::create(0);
    scan->setName("ct");
    auto acc = scan->getAccessor();
    std::mt19937 rng(3);
    for (int i = 0; i < 40; ++i)
        for (int j = 0; j < 36; ++j)
            for (int k = 0; k < 30; ++k) {
                const int core = (i - 20) * (i - 20) + (j - 18) * (j - 18) + (k - 15) * (k - 15) < 64 ? 1200 : 0;
                acc.setValue(openvdb::Coord(i, j, k), int(rng() % 400) - 1000 + core);
            }
    for (const auto& [grid, name] : {std::pair<openvdb::GridBase::Ptr, std::string>{fog, "vdbdag_vk_mip_fog"}, {scan, "vdbdag_vk_mip_ct"}})
      for (const trace::Shading shading : {trace::Shading::Mip, trace::Shading::Slice}) {
        const format::EncodedGrid encoded = encodeVdbGrid(grid, name);
        const trace::RenderGrid rg = trace::makeRenderGrid(encoded, shading);
        ASSERT_TRUE(shading == trace::Shading::Mip ? rg.mip : rg.slice);
        const trace::Camera camera = trace::frameBounds(trace::GridFrame(rg.indexToWorld), rg.cellLo, rg.cellHi, 96, 72);
        gpu::VulkanTracer gpuTracer(*context(), rg);
        for (const auto& window : {std::optional<std::pair<double, double>>{}, std::optional(std::pair{-500.0, 100.0})}) {
            trace::RenderOptions options;
            options.window = window;
            gpuTracer.setFloatWalk(window.has_value());  // both arithmetics of the walk, the same image
            // A slice through the middle, seen from the default camera's slant.
            options.slice = {1 + int(window.has_value()), grid == scan ? 15 : 0};
            trace::RenderStats cpuStats, gpuStats;
            const trace::Image cpu = trace::renderCpu(rg, camera, options, &cpuStats);
            const trace::Image gpu = gpuTracer.render(rg, camera, options, gpuStats);
            ASSERT_TRUE(cpuStats.window && gpuStats.window) << name;
            EXPECT_EQ(*gpuStats.window, *cpuStats.window) << name;
            EXPECT_EQ(gpu.rgb, cpu.rgb) << name;
            EXPECT_EQ(gpu.alpha, cpu.alpha) << name;
            EXPECT_GT(std::count(cpu.alpha.begin(), cpu.alpha.end(), 1.0f), 100) << name;
        }
      }
}

// --shading labels: the first voxel whose label is shown, found on the GPU
// and shaded as the CPU does: identical images, with every label shown and
// with a chosen few.
TEST(VulkanTracer, LabelsEqualTheCpuRenderer) {
    VULKAN_OR_SKIP();
    openvdb::initialize();
    auto atlas = openvdb::Int32Grid::create(0);
    atlas->setName("atlas");
    auto acc = atlas->getAccessor();
    for (int i = 0; i < 48; ++i)
        for (int j = 0; j < 40; ++j)
            for (int k = 0; k < 36; ++k) {
                // Nested shells of labels 1..4 around two centres, 7 in a slab, 0 elsewhere (still active: a dense atlas).
                const int r1 = (i - 16) * (i - 16) + (j - 20) * (j - 20) + (k - 18) * (k - 18), r2 = (i - 34) * (i - 34) + (j - 18) * (j - 18) + (k - 16) * (k - 16);
                const int label = r1 < 49 ? 1 + r1 / 13 : r2 < 64 ? 3 + r2 / 33 : (j > 30 && k < 8) ? 7 : 0;
                acc.setValue(openvdb::Coord(i, j, k), label);
            }
    const format::EncodedGrid encoded = encodeVdbGrid(atlas, "vdbdag_vk_labels");
    const trace::RenderGrid rg = trace::makeRenderGrid(encoded, trace::Shading::Labels);
    ASSERT_TRUE(rg.labels);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(rg.indexToWorld), rg.cellLo, rg.cellHi, 96, 72);
    gpu::VulkanTracer gpuTracer(*context(), rg);
    for (const std::vector<int64_t>& shown : {std::vector<int64_t>{}, std::vector<int64_t>{2, 7}}) {
        trace::RenderOptions options;
        options.labels = shown;
        gpuTracer.setFloatWalk(!shown.empty());  // both arithmetics of the walk, the same image
        trace::RenderStats stats;
        const trace::Image cpu = trace::renderCpu(rg, camera, options);
        const trace::Image gpu = gpuTracer.render(rg, camera, options, stats);
        EXPECT_EQ(gpu.rgb, cpu.rgb) << shown.size();
        EXPECT_EQ(gpu.alpha, cpu.alpha) << shown.size();
        EXPECT_EQ(gpu.depth, cpu.depth) << shown.size();
        EXPECT_EQ(gpu.normal, cpu.normal) << shown.size();
        EXPECT_GT(std::count(cpu.alpha.begin(), cpu.alpha.end(), 1.0f), 200) << shown.size();
    }
}

// --shading iso: the first crossing of the value, found on the GPU (the
// interpolated t between touching boxes in the same arithmetic) and shaded
// as the CPU does: identical images, at the automatic and a given value.
TEST(VulkanTracer, IsosurfaceEqualsTheCpuRenderer) {
    VULKAN_OR_SKIP();
    openvdb::initialize();
    auto scan = openvdb::FloatGrid::create(0.0f);
    scan->setName("ct");
    auto acc = scan->getAccessor();
    std::mt19937 rng(5);
    for (int i = 0; i < 44; ++i)
        for (int j = 0; j < 40; ++j)
            for (int k = 0; k < 32; ++k) {
                const double r = std::sqrt((i - 22.0) * (i - 22.0) + (j - 19.0) * (j - 19.0) + 1.6 * (k - 15.0) * (k - 15.0));
                acc.setValue(openvdb::Coord(i, j, k), float(1000.0 / (1.0 + std::exp(r - 12.0)) + double(rng() % 50)));
            }
    const format::EncodedGrid encoded = encodeVdbGrid(scan, "vdbdag_vk_iso");
    const trace::RenderGrid rg = trace::makeRenderGrid(encoded, trace::Shading::Iso);
    ASSERT_TRUE(rg.iso);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(rg.indexToWorld), rg.cellLo, rg.cellHi, 96, 72);
    gpu::VulkanTracer gpuTracer(*context(), rg);
    for (const std::optional<double> iso : {std::optional<double>{}, std::optional(420.5)}) {
        trace::RenderOptions options;
        options.iso = iso;
        gpuTracer.setFloatWalk(iso.has_value());  // both arithmetics of the walk, the same image
        trace::RenderStats cpuStats, gpuStats;
        const trace::Image cpu = trace::renderCpu(rg, camera, options, &cpuStats);
        const trace::Image gpu = gpuTracer.render(rg, camera, options, gpuStats);
        ASSERT_TRUE(cpuStats.iso && gpuStats.iso);
        EXPECT_EQ(*gpuStats.iso, *cpuStats.iso);
        EXPECT_EQ(gpu.rgb, cpu.rgb);
        EXPECT_EQ(gpu.alpha, cpu.alpha);
        EXPECT_EQ(gpu.depth, cpu.depth);
        EXPECT_EQ(gpu.normal, cpu.normal);
        EXPECT_GT(std::count(cpu.alpha.begin(), cpu.alpha.end(), 1.0f), 300);
    }
}

// --shading volume: emission-absorption through the transfer function, lit
// by the values' gradient, on the GPU (pow as exp and log in double there):
// the same coverage and depth, colours within 1e-6, with the automatic
// ramp and with control points.
TEST(VulkanTracer, VolumeRenderingAgreesWithTheCpuRenderer) {
    VULKAN_OR_SKIP();
    openvdb::initialize();
    auto scan = openvdb::FloatGrid::create(0.0f);
    scan->setName("ct");
    auto acc = scan->getAccessor();
    std::mt19937 rng(9);
    for (int i = 0; i < 40; ++i)
        for (int j = 0; j < 36; ++j)
            for (int k = 0; k < 30; ++k) {
                const double r = std::sqrt((i - 20.0) * (i - 20.0) + (j - 17.0) * (j - 17.0) + 1.3 * (k - 14.0) * (k - 14.0));
                acc.setValue(openvdb::Coord(i, j, k), float(900.0 / (1.0 + std::exp(r - 17.0)) + 300.0 * (r < 7) + double(rng() % 60)));
            }
    const format::EncodedGrid encoded = encodeVdbGrid(scan, "vdbdag_vk_volume");
    const trace::RenderGrid rg = trace::makeRenderGrid(encoded, trace::Shading::Volume);
    ASSERT_TRUE(rg.volume);
    const trace::Camera camera = trace::frameBounds(trace::GridFrame(rg.indexToWorld), rg.cellLo, rg.cellHi, 96, 72);
    gpu::VulkanTracer gpuTracer(*context(), rg);
    trace::TransferFunction points{100, 1200, {{100, 0.1, 0.0, 0.0}, {600, 0.8, 0.5, 0.2}, {1200, 1.0, 1.0, 0.9}}, {{150, 0.0}, {500, 0.05}, {1100, 0.3}}};
    for (const std::optional<trace::TransferFunction>& tf : {std::optional<trace::TransferFunction>{}, std::optional(points)}) {
        trace::RenderOptions options;
        options.transfer = tf;
        gpuTracer.setFloatWalk(tf.has_value());  // both arithmetics of the walk, the same image
        trace::RenderStats cpuStats, gpuStats;
        const trace::Image cpu = trace::renderCpu(rg, camera, options, &cpuStats);
        const trace::Image gpu = gpuTracer.render(rg, camera, options, gpuStats);
        EXPECT_EQ(*gpuStats.window, *cpuStats.window);
        expectSameImage(gpu, cpu, 1e-6, tf ? "volume, control points" : "volume, automatic ramp");
    }
}

