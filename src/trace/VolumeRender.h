// Emission-absorption volume rendering of scalar grids (`render --shading
// volume`): a transfer function gives each value a colour and an opacity -
// transparent at or below `low` (a CT's air), then an opacity per voxel
// length growing with the square of the value's place in [low, high] up to
// kMaxOpacity (soft tissue faint, bone nearly opaque), and a colour from
// dark red to ivory over the same range - lit by the values' gradient
// (Lambert, the surfaces' light) and composited front to back along the
// boxes each ray crosses until nearly opaque. The window [low, high] is
// --window, else Otsu's threshold of the values to their 99.5th percentile.
// The CPU tracer only.
#pragma once
#include <utility>

#include <glm/glm.hpp>

#include "src/trace/Camera.h"
#include "src/trace/Image.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/Shading.h"

namespace vdbdag::trace {

inline constexpr double kMaxOpacity = 0.35;  // per voxel length, at `high` and above

struct TransferFunction {
    double low = 0, high = 1;
    // Opacity per voxel length of a value (0 at or below low, NaN too).
    double opacity(double v) const;
    // Linear RGB of a value (clamped to [low, high]).
    glm::dvec3 colour(double v) const;
};

// The default window: Otsu's threshold of the stored values (a sample of at
// most 2^20 entries) to their 99.5th percentile.
TransferFunction automaticTransfer(const RenderGrid& grid);

Image renderVolume(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, const TransferFunction& tf);

} // namespace vdbdag::trace
