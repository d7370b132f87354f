// One slice of a grid (`render --shading slice --slice z=40`): the plane
// through the centres of the voxels whose index on an axis is given, seen
// by the camera (by default straight along that axis). Each pixel shows the
// value of the voxel its ray meets the plane in, as grey through the window
// (--window LOW,HIGH, else Otsu's threshold of the slice's values to their
// 99.5th percentile: air black, tissue grey to white); where the ray meets
// the plane outside the stored voxels, or not at all, it is transparent.
// The Vulkan tracer finds the same voxels (trace.comp SLICE).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "src/trace/Camera.h"
#include "src/trace/Projection.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/Shading.h"

namespace vdbdag::trace {

// Parses "x=12", "y=-3", "z=40" (Error otherwise).
SlicePlane parseSlicePlane(const std::string& text);

// Per pixel, row-major: the value of the voxel where the ray meets the
// plane; NaN where it meets no stored voxel there.
std::vector<double> sliceValues(const RenderGrid& grid, const Camera& camera, const SlicePlane& plane);

Projection renderSlice(const RenderGrid& grid, const Camera& camera, const SlicePlane& plane, std::optional<std::pair<double, double>> window);

} // namespace vdbdag::trace
