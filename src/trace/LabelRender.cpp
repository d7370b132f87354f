// See LabelRender.h.
#include "src/trace/LabelRender.h"

#include <algorithm>
#include <cmath>

#include "src/trace/PixelSegments.h"

namespace vdbdag::trace {

std::vector<std::optional<LabelHit>> firstLabels(const RenderGrid& grid, const Camera& camera, const std::vector<int64_t>& shown) {
    std::vector<std::optional<LabelHit>> hits(size_t(camera.width) * size_t(camera.height));
    const auto isShown = [&](int64_t label) {
        if (!shown.empty()) return std::find(shown.begin(), shown.end(), label) != shown.end();
        return label != 0 && label != grid.labelBackground;
    };
    forEachPixelSegment(grid, camera, [&](size_t pixel, const RayHit& box, double v, double) {
        const int64_t label = std::isfinite(v) ? int64_t(v) : 0;
        if (!isShown(label)) return false;
        hits[pixel] = LabelHit{box, label};
        return true;
    });
    return hits;
}

glm::dvec3 labelColour(int64_t label) {
    // splitmix64 of the label: a stable hue; saturation 0.65, value 0.9.
    uint64_t z = uint64_t(label) + 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    const double h = double(z >> 11) / double(uint64_t(1) << 53) * 6.0, s = 0.65, v = 0.9;
    const int sector = int(h) % 6;
    const double f = h - std::floor(h), p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    glm::dvec3 rgb;
    switch (sector) {
        case 0: rgb = {v, t, p}; break;
        case 1: rgb = {q, v, p}; break;
        case 2: rgb = {p, v, t}; break;
        case 3: rgb = {p, q, v}; break;
        case 4: rgb = {t, p, v}; break;
        default: rgb = {v, p, q}; break;
    }
    return glm::pow(rgb, glm::dvec3(2.2));  // to linear light
}

Image renderLabels(const RenderGrid& grid, const Camera& camera, const RenderOptions& options) {
    return shadeLabels(grid, camera, options, firstLabels(grid, camera, options.labels));
}

Image shadeLabels(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, const std::vector<std::optional<LabelHit>>& hits) {
    const GridFrame frame(grid.indexToWorld);
    const glm::dvec3 light = defaultLight(camera.eye, camera.target, camera.up);
    Image image;
    image.resize(camera.width, camera.height);
    for (int py = 0; py < camera.height; ++py)
        for (int px = 0; px < camera.width; ++px) {
            const size_t i = size_t(py) * size_t(camera.width) + size_t(px);
            glm::dvec3 colour = options.background;
            if (const std::optional<LabelHit>& h = hits[i]) {
                glm::dvec3 eye, dir;
                camera.pixelRay(px, py, eye, dir);
                const glm::dvec3 normal = facingNormal(frame, h->box, dir);
                const double lambert = std::max(0.0, glm::dot(normal, light));
                colour = labelColour(h->label) * (kAmbient + (1 - kAmbient) * lambert);
                image.alpha[i] = 1;
                image.depth[i] = float(h->box.t);
                for (int a = 0; a < 3; ++a) image.normal[3 * i + size_t(a)] = float(normal[a]);
            }
            for (int a = 0; a < 3; ++a) image.rgb[3 * i + size_t(a)] = float(colour[a]);
        }
    return image;
}

} // namespace vdbdag::trace
