// The render backends behind `vdbdag render` and `vdbdag bench`: the CPU
// reference tracer, or the Vulkan compute backend (gpu/).
#pragma once
#include <memory>
#include <string>

#include "app/RenderFile.h"

namespace vdbdag::cli {

using RenderBackend = app::RenderBackend;  // the interface (app/RenderFile.h)

// "cpu", "vulkan", or "auto" (a Vulkan GPU when one exists, else the CPU
// tracer with a one-line note on stderr: a software Vulkan device is used
// only when asked for); `device` >= 0 picks a Vulkan device (--device N).
std::unique_ptr<RenderBackend> makeRenderBackend(const std::string& kind, int device);

} // namespace vdbdag::cli
