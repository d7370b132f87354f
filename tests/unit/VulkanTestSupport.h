// What the Vulkan tests share: one device context for the whole test
// program (null without a device: VULKAN_OR_SKIP), grids written through a
// real .vdb and imported as `encode` imports them, and an image comparison.
#pragma once
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include <openvdb/openvdb.h>

#include "gpu/VulkanContext.h"
#include "src/pipeline/GridCodec.h"
#include "src/trace/Image.h"
#include "src/util/Error.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::testing {

// One context for the whole file (device creation costs ~0.1 s); null without a device.
inline gpu::VulkanContext* context() {
    static std::unique_ptr<gpu::VulkanContext> ctx = [] {
        try {
            return std::make_unique<gpu::VulkanContext>();
        } catch (const Error& e) {
            const std::string m = e.what();
            if (m.starts_with("no Vulkan device found") || m.starts_with("no usable Vulkan device")) return std::unique_ptr<gpu::VulkanContext>();
            throw;
        }
    }();
    return ctx.get();
}

#define VULKAN_OR_SKIP()                                                         \
    if (!vdbdag::testing::context()) GTEST_SKIP() << "no Vulkan device on this machine";

// Writes `grids` to a temporary .vdb and imports it back.
inline bridge::ImportResult importVdbGrids(const openvdb::GridPtrVec& grids, const std::string& name, const bridge::ImportOptions& options = {}) {
    const std::filesystem::path path = std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".vdb");
    openvdb::io::File file(path.string());
    file.write(grids);
    file.close();
    auto imported = bridge::importVdb(path.string(), options);
    std::filesystem::remove(path);
    return imported;
}

inline format::EncodedGrid encodeVdbGrid(openvdb::GridBase::Ptr grid, const std::string& name) {
    return pipeline::encodeGrid(importVdbGrids({grid}, name).volume.grids.at(0));
}

// Compares two renders: identical coverage, small colour difference.
inline void expectSameImage(const trace::Image& gpu, const trace::Image& cpu, double maxColourDiff, const std::string& label) {
    ASSERT_EQ(gpu.width, cpu.width);
    ASSERT_EQ(gpu.height, cpu.height);
    size_t covered = 0, coverageDiff = 0;
    double worst = 0;
    for (size_t i = 0; i < cpu.alpha.size(); ++i) {
        covered += cpu.alpha[i] > 0;
        coverageDiff += (gpu.alpha[i] > 0) != (cpu.alpha[i] > 0);
        worst = std::max(worst, double(std::fabs(gpu.alpha[i] - cpu.alpha[i])));
        for (int a = 0; a < 3; ++a) {
            worst = std::max(worst, double(std::fabs(gpu.rgb[3 * i + a] - cpu.rgb[3 * i + a])));
            worst = std::max(worst, double(std::fabs(gpu.normal[3 * i + a] - cpu.normal[3 * i + a])));
        }
        if (std::isfinite(cpu.depth[i]) || std::isfinite(gpu.depth[i])) { EXPECT_EQ(gpu.depth[i], cpu.depth[i]) << label << " pixel " << i; }
    }
    EXPECT_GT(covered, cpu.alpha.size() / 10) << label;
    EXPECT_EQ(coverageDiff, 0u) << label;
    EXPECT_LE(worst, maxColourDiff) << label;
}

} // namespace vdbdag::testing
