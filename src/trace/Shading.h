// Shading shared by the CPU renderer and (line by line) the Vulkan shader:
// base colours from values, Lambert with one directional light, and the
// emission-absorption step of fog volumes.
#pragma once
#include <glm/glm.hpp>

#include "src/trace/RenderGrid.h"

namespace vdbdag::trace {

struct RenderOptions {
    double lodPixels = 0;       // LOD cut-off: a node smaller than this many pixels is a hit (0: off)
    bool shadows = false;       // secondary ray towards the light
    double densityScale = 0.08; // fog: extinction per voxel length at the grid's largest density
    glm::dvec3 background{0.10, 0.11, 0.13};
};

inline constexpr double kAmbient = 0.2;
// Level-set shadow rays skip voxels within this many voxel lengths of their
// start: the narrow band's staircase would otherwise shadow its own surface.
inline constexpr double kShadowBias = 3.0;
// ... and start this many voxels off the surface along its gradient.
inline constexpr double kShadowNormalOffset = 1.5;
inline const glm::dvec3 kMaterial{0.80, 0.78, 0.74};
inline const glm::dvec3 kFogEmission{0.92, 0.92, 0.95};

// Linear RGB base colour of a hit's value.
glm::dvec3 baseColour(const RenderGrid& grid, uint64_t attribute);

// Direction towards the light for a camera: over the viewer's left shoulder.
glm::dvec3 defaultLight(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up);

} // namespace vdbdag::trace
