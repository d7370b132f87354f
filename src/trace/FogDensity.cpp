// See FogDensity.h.
#include "src/trace/FogDensity.h"

#include <algorithm>
#include <vector>

#include "src/trace/DagTracer.h"

namespace vdbdag::trace {

double autoDensityScale(const RenderGrid& grid, const Camera& camera, double fallback) {
    if (!grid.fog || !(grid.valueMax > 0) || camera.width <= 0 || camera.height <= 0) return fallback;
    const GridFrame frame(grid.indexToWorld);
    const DagTracer tracer(*grid.dag);
    // Optical depth at densityScale 1: renderCpu's scale * density * dt with
    // scale = 1 / (valueMax * voxelSize), summed along the ray.
    const double unit = 1.0 / (grid.valueMax * frame.voxelSize());
    const int nx = std::min(camera.width, 48), ny = std::min(camera.height, 48);
    std::vector<double> depths;
    depths.reserve(size_t(nx) * size_t(ny));
    size_t hint = 0;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const int px = int((int64_t(2 * i + 1) * camera.width) / (2 * nx)), py = int((int64_t(2 * j + 1) * camera.height) / (2 * ny));
            glm::dvec3 eye, dir;
            camera.pixelRay(px, py, eye, dir);
            double depth = 0;
            tracer.forEachSegment(frame.toCellRay(eye, dir), [&](const RayHit& box, double tLeave) {
                depth += unit * std::max(0.0, valueAsDoubles(grid, box.attribute, hint)[0]) * (tLeave - box.t);
                return false;
            });
            if (depth > 0) depths.push_back(depth);
        }
    if (depths.empty()) return fallback;
    const auto mid = depths.begin() + long(depths.size() / 2);
    std::nth_element(depths.begin(), mid, depths.end());
    return std::clamp(1.0 / *mid, 1e-9, 1e6);
}

} // namespace vdbdag::trace
