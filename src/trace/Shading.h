// Shading shared by the CPU renderer and (line by line) the Vulkan shader,
// whose constants both include from shading_constants.h:
// base colours from values, Lambert with one directional light, and the
// emission-absorption step of fog volumes.
#pragma once
#include <optional>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "src/trace/Camera.h"
#include "src/trace/Ray.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/TransferFunction.h"
#include "src/trace/shading_constants.h"

namespace vdbdag::trace {

// A slice of a grid: the voxels whose index on `axis` (0 x, 1 y, 2 z) is `index`.
struct SlicePlane {
    int axis = 2;
    int64_t index = 0;
};

struct RenderOptions {
    double lodPixels = 0;       // LOD cut-off: a node smaller than this many pixels is a hit (0: off)
    bool shadows = false;       // secondary ray towards the light
    double densityScale = 0.08; // fog: extinction per voxel length at the grid's largest density
    glm::dvec3 background{0.10, 0.11, 0.13};
    // --shading mip: the display window [low, high] (Projection.h; chosen
    // from the image when absent); --shading volume: the transfer
    // function's window (VolumeRender.h; chosen from the values);
    // --shading slice: the grey window (SliceView.h).
    std::optional<std::pair<double, double>> window;
    // --shading volume: a transfer function read from a file (--tf), used
    // instead of the window's ramp.
    std::optional<TransferFunction> transfer;
    // --shading labels: the labels shown (`--labels`; empty: every one but 0 and the background).
    std::vector<int64_t> labels;
    // --shading iso: the surface's value (`--iso`; IsoSurface.h's automaticIso when absent).
    std::optional<double> iso;
    // --shading slice: the plane shown (`--slice`; SliceView.h).
    SlicePlane slice;
};

using access::kAmbient;
using access::kShadowBias;
using access::kShadowNormalOffset;
// A colour of shading_constants.h as a glm vector.
constexpr glm::dvec3 rgb(const double (&c)[3]) { return {c[0], c[1], c[2]}; }
inline const glm::dvec3 kMaterial = rgb(access::kMaterialRgb);
inline const glm::dvec3 kFogEmission = rgb(access::kFogEmissionRgb);

// The scalar colour map (ParaView's "Cool to Warm") at s in [0, 1] (clamped; NaN: 0).
glm::dvec3 coolToWarm(double s);

// Linear RGB base colour of a hit's value.
glm::dvec3 baseColour(const RenderGrid& grid, uint64_t attribute);

// A first hit's world-space normal turned towards the viewer (whose ray
// goes along `dir`): `indexNormal` (an index-space gradient) when given,
// else the face the ray entered through, else -dir (a ray starting inside).
glm::dvec3 facingNormal(const GridFrame& frame, const RayHit& hit, const glm::dvec3& dir, const std::optional<glm::dvec3>& indexNormal = std::nullopt);

// Direction towards the light for a camera: over the viewer's left shoulder.
glm::dvec3 defaultLight(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up);

} // namespace vdbdag::trace
