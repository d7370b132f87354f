// Emission-absorption volume rendering of scalar grids (`render --shading
// volume`): a transfer function (TransferFunction.h: a ramp over a window,
// or the points of a `--tf` file) gives each value a colour and an opacity,
// lit by the values' gradient (Lambert, the surfaces' light) and composited
// front to back along the boxes each ray crosses until nearly opaque. The
// ramp's window [low, high] is --window, else Otsu's threshold of the values
// to their 99.5th percentile. The Vulkan tracer renders the same (trace.comp
// VOLUME: pow through exp and log in double, colours within 1e-6).
#pragma once
#include <utility>

#include <glm/glm.hpp>

#include "src/trace/Camera.h"
#include "src/trace/Image.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/Shading.h"
#include "src/trace/TransferFunction.h"

namespace vdbdag::trace {

// The default window: Otsu's threshold of the stored values (a sample of at
// most 2^20 entries) to their 99.5th percentile.
TransferFunction automaticTransfer(const RenderGrid& grid);
// The transfer function a render uses: --tf's, else the automatic one with
// --window's range when given (both tracers).
TransferFunction chosenTransfer(const RenderGrid& grid, const RenderOptions& options);

Image renderVolume(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, const TransferFunction& tf);

} // namespace vdbdag::trace
