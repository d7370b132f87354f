// See IsoSurface.h.
#include "src/trace/IsoSurface.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "src/trace/DagTracer.h"
#include "src/trace/PixelSegments.h"
#include "src/trace/Projection.h"
#include "src/trace/ValueGradient.h"

namespace vdbdag::trace {

std::vector<std::optional<IsoHit>> firstCrossings(const RenderGrid& grid, const Camera& camera, double iso) {
    const size_t pixels = size_t(camera.width) * size_t(camera.height);
    std::vector<std::optional<IsoHit>> hits(pixels);
    // Per pixel, the box before on the ray: its value, centre and exit.
    struct Before {
        double value = std::numeric_limits<double>::quiet_NaN(), centre = 0, leave = -1;
    };
    std::vector<Before> before(pixels);
    forEachPixelSegment(grid, camera, [&](size_t pixel, const RayHit& box, double v, double tLeave) {
        Before& b = before[pixel];
        if (!(v >= iso)) {  // below, or NaN
            b = {v, 0.5 * (box.t + tLeave), tLeave};
            return false;
        }
        double t = box.t;
        if (b.value < iso && b.leave == box.t) {  // touching boxes: between their centres
            const double centre = 0.5 * (box.t + tLeave);
            t = b.centre + (iso - b.value) / (v - b.value) * (centre - b.centre);
        }
        hits[pixel] = IsoHit{box, t};
        return true;
    });
    return hits;
}

double automaticIso(const RenderGrid& grid) {
    if (!grid.values || grid.values->entryCount == 0) return 0.5;
    return storedValueWindow(grid).first;
}

double chosenIso(const RenderGrid& grid, const RenderOptions& options) { return options.iso ? *options.iso : automaticIso(grid); }

Image renderIso(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, double iso) {
    return shadeIso(grid, camera, options, firstCrossings(grid, camera, iso));
}

Image shadeIso(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, const std::vector<std::optional<IsoHit>>& hits) {
    const GridFrame frame(grid.indexToWorld);
    const DagTracer tracer(*grid.dag);
    const glm::dvec3 light = defaultLight(camera.eye, camera.target, camera.up);
    Image image;
    image.resize(camera.width, camera.height);
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height, 4), [&](const tbb::blocked_range<int>& rows) {
        for (int py = rows.begin(); py != rows.end(); ++py)
            for (int px = 0; px < camera.width; ++px) {
                const size_t i = size_t(py) * size_t(camera.width) + size_t(px);
                glm::dvec3 colour = options.background;
                if (const std::optional<IsoHit>& h = hits[i]) {
                    glm::dvec3 eye, dir;
                    camera.pixelRay(px, py, eye, dir);
                    const std::optional<glm::dvec3> g = valueGradient(grid, tracer, h->box.voxel, valueAsDoubles(grid, h->box.attribute)[0]);
                    const glm::dvec3 normal = facingNormal(frame, h->box, dir, g ? std::optional(-*g) : std::nullopt);
                    const double lambert = std::max(0.0, glm::dot(normal, light));
                    colour = kMaterial * (kAmbient + (1 - kAmbient) * lambert);
                    image.alpha[i] = 1;
                    image.depth[i] = float(h->t);
                    for (int a = 0; a < 3; ++a) image.normal[3 * i + size_t(a)] = float(normal[a]);
                }
                for (int a = 0; a < 3; ++a) image.rgb[3 * i + size_t(a)] = float(colour[a]);
            }
    });
    return image;
}

} // namespace vdbdag::trace
