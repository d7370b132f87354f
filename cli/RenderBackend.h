// The render backends behind `vdbdag render` and `vdbdag bench`: the CPU
// reference tracer, or the Vulkan compute backend (gpu/).
#pragma once
#include <memory>
#include <string>

#include "src/trace/Camera.h"
#include "src/trace/CpuRenderer.h"

namespace vdbdag::cli {

class RenderBackend {
public:
    virtual ~RenderBackend() = default;
    virtual std::string name() const = 0;
    // What ran the frames: the Vulkan device's name, or the CPU's thread count.
    virtual std::string device() const = 0;
    virtual trace::Image render(const trace::RenderGrid& grid, const trace::Camera& camera, const trace::RenderOptions& options,
                                trace::RenderStats& stats) = 0;
};

// "cpu", "vulkan", or "auto" (a Vulkan GPU when one exists, else the CPU
// tracer with a one-line note on stderr: a software Vulkan device is used
// only when asked for); `device` >= 0 picks a Vulkan device (--device N).
std::unique_ptr<RenderBackend> makeRenderBackend(const std::string& kind, int device);

} // namespace vdbdag::cli
