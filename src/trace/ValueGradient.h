// The gradient of a grid's scalar values at a voxel, by central differences
// of the stored values of its six neighbours (one-sided where a neighbour is
// not stored), looked up in the DAG: the normal of level sets (CpuRenderer),
// isosurfaces (IsoSurface.h) and volume rendering (VolumeRender.h).
#pragma once
#include <array>
#include <cstdint>
#include <optional>

#include <glm/glm.hpp>

#include "src/trace/DagTracer.h"
#include "src/trace/RenderGrid.h"

namespace vdbdag::trace {

// In index space, unit length; nullopt where it vanishes or is not finite.
// `centre`: the voxel's own value.
std::optional<glm::dvec3> valueGradient(const RenderGrid& grid, const DagTracer& tracer, const std::array<int64_t, 3>& voxel, double centre);

} // namespace vdbdag::trace
