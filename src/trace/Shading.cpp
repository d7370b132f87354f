// Base colours and light; see Shading.h. Keep in step with gpu/shaders/trace.comp.
#include "src/trace/Shading.h"

#include <algorithm>
#include <cmath>

namespace vdbdag::trace {

// shading_constants.h spells its doubles as integer ratios (for GLSL): they are
// the nearest doubles to the decimals they stand for.
static_assert(kAmbient == 0.2 && access::kMaterialRgb[1] == 0.78 && access::kWarmRgb[1] == 0.02 && access::kFogEmissionRgb[2] == 0.95);

glm::dvec3 coolToWarm(double s) {
    // ParaView's "Cool to Warm", as three stops.
    s = std::isfinite(s) ? std::clamp(s, 0.0, 1.0) : 0.0;
    const glm::dvec3 cool = rgb(access::kCoolRgb), mid = rgb(access::kMidRgb), warm = rgb(access::kWarmRgb);
    return s < 0.5 ? glm::mix(cool, mid, s * 2) : glm::mix(mid, warm, s * 2 - 1);
}

glm::dvec3 facingNormal(const GridFrame& frame, const RayHit& hit, const glm::dvec3& dir, const std::optional<glm::dvec3>& indexNormal) {
    glm::dvec3 normal = -dir;
    if (indexNormal) {
        normal = frame.normalToWorld(*indexNormal);
    } else if (hit.faceAxis >= 0) {
        glm::dvec3 n(0);
        n[hit.faceAxis] = hit.faceSign;
        normal = frame.normalToWorld(n);
    }
    return glm::dot(normal, dir) > 0 ? -normal : normal;
}

glm::dvec3 baseColour(const RenderGrid& grid, uint64_t attribute) {
    switch (grid.colouring) {
    case ValueColouring::None: return kMaterial;
    case ValueColouring::Scalar: {
        const double v = valueAsDoubles(grid, attribute)[0];
        return coolToWarm((v - grid.valueMin) / (grid.valueMax - grid.valueMin));
    }
    case ValueColouring::Colour: {
        const auto c = valueAsDoubles(grid, attribute);
        const double scale = grid.valueType == ValueType::Vec3I ? 1.0 / 255.0 : 1.0;
        glm::dvec3 out;
        for (int a = 0; a < 3; ++a) out[a] = std::isfinite(c[a]) ? std::clamp(c[a] * scale, 0.0, 1.0) : 0.0;
        return out;
    }
    case ValueColouring::Vector: {
        const auto c = valueAsDoubles(grid, attribute);
        glm::dvec3 v{c[0], c[1], c[2]};
        const double len = glm::length(v);
        if (!(len > 0) || !std::isfinite(len)) return glm::dvec3(0.5);
        return glm::dvec3(0.5) + 0.5 * v / len;
    }
    }
    return kMaterial;
}

glm::dvec3 defaultLight(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up) {
    const glm::dvec3 back = glm::normalize(eye - target);
    const glm::dvec3 right = glm::normalize(glm::cross(-back, up));
    return glm::normalize(0.7 * back + 0.9 * glm::normalize(up) - 0.8 * right);
}

} // namespace vdbdag::trace
