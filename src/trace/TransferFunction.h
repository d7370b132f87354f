// What a volume render (VolumeRender.h, `render --shading volume`) gives
// each value: an opacity per voxel length and a linear-light colour. By
// default a ramp over a window [low, high]: transparent at or below `low`
// (a CT's air), opacity growing with the square of the value's place in the
// window up to kMaxOpacity (soft tissue faint, bone nearly opaque), colour
// from dark red to ivory. Or, read from a file (`render --tf FILE`,
// readTransferFunction), piecewise-linear colour and opacity points.
#pragma once
#include "src/trace/shading_constants.h"
#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace vdbdag::trace {

inline constexpr double kMaxOpacity = access::kMaxOpacity;  // 0.35 per voxel length, at `high` and above (shading_constants.h: the shader's too)

struct TransferFunction {
    double low = 0, high = 1;
    // Control points (value ascending), used instead of the ramp when given:
    // (value, linear r, g, b) and (value, opacity per voxel length). Between
    // points linear, beyond the ends the end's.
    std::vector<std::array<double, 4>> colourPoints;
    std::vector<std::array<double, 2>> opacityPoints;
    // Opacity per voxel length of a value (NaN: 0).
    double opacity(double v) const;
    // Linear RGB of a value.
    glm::dvec3 colour(double v) const;
};

// A ParaView colour-map preset as ParaView exports it (a JSON object, or an
// array whose first object is used): "RGBPoints" [x, r, g, b, ...] in
// display (sRGB) colours, made linear here, and optional "Points" [x,
// opacity, midpoint, sharpness, ...] (midpoint and sharpness ignored: linear
// between points), an opacity of 1 meaning kMaxOpacity per voxel length;
// without "Points" the default ramp's opacity over the colour points' range.
// low/high become the first and last colour point's values. Throws
// vdbdag::Error naming `path` on a missing file, bad JSON, fewer than two
// colour points, lengths that are not multiples of 4, values that are not
// finite or not ascending.
TransferFunction readTransferFunction(const std::string& path);

} // namespace vdbdag::trace
