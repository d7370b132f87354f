// The default density scale of a fog render (RenderOptions::densityScale):
// the one at which the median optical depth of the camera's rays that
// meet the fog is 1, so a fog looks like fog (half its rays let through
// more than e^-1 of the light behind) whatever its densities and size. A
// fixed scale saturated large or dense fogs to a flat white cut-out.
#pragma once
#include "src/trace/Camera.h"
#include "src/trace/RenderGrid.h"

namespace vdbdag::trace {

// Median over a lattice of up to 48 x 48 of the camera's rays, each traced
// as renderCpu traces a fog (DagTracer::forEachSegment, the same optical
// depth per segment); `fallback` when no ray meets a positive density.
double autoDensityScale(const RenderGrid& grid, const Camera& camera, double fallback);

} // namespace vdbdag::trace
