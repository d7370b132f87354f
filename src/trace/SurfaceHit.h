// The surface a ray sees in a grid: the first active voxel, or, for a level
// set, the first active voxel whose value is <= 0 - the zero crossing, as
// NanoVDB's ZeroCrossing finds it - walking past the narrow band's outside
// voxels. Used for primary and shadow rays by the CPU renderer and the
// benchmarks.
#pragma once
#include "src/trace/DagTracer.h"
#include "src/trace/RenderGrid.h"

namespace vdbdag::trace {

// Boxes entered before `ignoreBefore` are skipped (a shadow ray's bias).
RayHit firstSurfaceHit(const RenderGrid& grid, const DagTracer& tracer, const Ray& ray, double ignoreBefore = 0);

} // namespace vdbdag::trace
