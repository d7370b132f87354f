// Backend selection for rendering; see RenderBackend.h.
#include "cli/RenderBackend.h"

#include "cli/GlobalOptions.h"

#include <thread>

#include <fmt/core.h>

#include "gpu/DeviceInfo.h"
#include "gpu/VulkanTracer.h"
#include "src/util/Error.h"

namespace vdbdag::cli {
namespace {

class CpuBackend final : public RenderBackend {
public:
    std::string name() const override { return "cpu"; }
    std::string device() const override { return fmt::format("CPU, {} hardware threads", std::thread::hardware_concurrency()); }
    trace::Image render(const trace::RenderGrid& grid, const trace::Camera& camera, const trace::RenderOptions& options,
                        trace::RenderStats& stats) override {
        return trace::renderCpu(grid, camera, options, &stats);
    }
};

// The Vulkan tracer (gpu/VulkanTracer): the device is opened at once (so a
// missing device is known before rendering), the grid uploaded on the first
// frame and kept for the next ones.
class VulkanBackend final : public RenderBackend {
public:
    explicit VulkanBackend(int device) {
        if (device >= 0) options_.deviceIndex = uint32_t(device);
        info_ = gpu::openDevice(options_);
    }
    std::string name() const override { return "vulkan"; }
    std::string device() const override { return info_.name; }
    // "CPU" for a software Vulkan device (lavapipe/llvmpipe).
    const std::string& deviceType() const { return info_.type; }
    trace::Image render(const trace::RenderGrid& grid, const trace::Camera& camera, const trace::RenderOptions& options,
                        trace::RenderStats& stats) override {
        if (!tracer_ || uploaded_ != grid.dag) {
            tracer_ = std::make_unique<gpu::VulkanTracer>(options_, grid);
            uploaded_ = grid.dag;
            // The first frame compiles the pipeline: warm it up outside the timing.
            trace::Camera tiny = camera;
            tiny.width = tiny.height = 8;
            trace::RenderStats ignored;
            tracer_->render(grid, tiny, options, ignored);
        }
        return tracer_->render(grid, camera, options, stats);
    }

private:
    gpu::ContextOptions options_;
    gpu::DeviceInfo info_;
    std::unique_ptr<gpu::VulkanTracer> tracer_;
    const encoding::CompactDag* uploaded_ = nullptr;
};

} // namespace

std::unique_ptr<RenderBackend> makeRenderBackend(const std::string& kind, int device) {
    if (kind == "cpu") return std::make_unique<CpuBackend>();
    if (kind == "vulkan") return std::make_unique<VulkanBackend>(device);
    // auto: a Vulkan GPU when one exists, else the CPU tracer with a note. A
    // software Vulkan device (lavapipe) is slower than the CPU tracer (387
    // against 108 ms a frame on the bunny), so auto never picks it; it is
    // used only when asked for (--backend vulkan, or --device N). An
    // explicit --device N that does not work is an error, not a fallback.
    if (device >= 0) return std::make_unique<VulkanBackend>(device);
    try {
        auto vulkan = std::make_unique<VulkanBackend>(device);
        if (vulkan->deviceType() == "CPU") {
            note(fmt::format("the only Vulkan device ({}) emulates a GPU on the CPU; rendering with the CPU tracer (--backend vulkan to use it)",
                             vulkan->device()));
            return std::make_unique<CpuBackend>();
        }
        return vulkan;
    } catch (const Error& e) {
        note(fmt::format("no Vulkan device ({}); rendering with the CPU tracer", e.what()));
        return std::make_unique<CpuBackend>();
    }
}

} // namespace vdbdag::cli
