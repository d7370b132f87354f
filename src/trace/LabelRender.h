// Label grids (atlases, segmentations: `render --shading labels`): each
// pixel shows the first voxel along its ray whose label is shown - any but
// 0 and the grid's background, or only those of `--labels` - in a stable
// categorical colour of its label (a hash, so a label keeps its colour
// across files and views), lit by its entry face as surfaces are. The
// Vulkan tracer finds the same first voxels and shades them with
// shadeLabels.
#pragma once
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "src/trace/Camera.h"
#include "src/trace/Image.h"
#include "src/trace/Ray.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/Shading.h"

namespace vdbdag::trace {

// Per pixel, row-major: the first shown voxel or tile along the ray and
// its label; no hit where none is met.
struct LabelHit {
    RayHit box;
    int64_t label = 0;
};
std::vector<std::optional<LabelHit>> firstLabels(const RenderGrid& grid, const Camera& camera, const std::vector<int64_t>& shown);

// A label's colour (linear RGB): its hash's hue, fixed saturation and value.
glm::dvec3 labelColour(int64_t label);

// The image of those hits: each its label's colour, lit by its entry face.
Image shadeLabels(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, const std::vector<std::optional<LabelHit>>& hits);
Image renderLabels(const RenderGrid& grid, const Camera& camera, const RenderOptions& options);

} // namespace vdbdag::trace
