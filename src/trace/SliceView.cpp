// See SliceView.h.
#include "src/trace/SliceView.h"

#include <charconv>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "src/trace/DagTracer.h"
#include "src/util/Error.h"

namespace vdbdag::trace {

SlicePlane parseSlicePlane(const std::string& text) {
    SlicePlane p;
    const char* end = text.data() + text.size();
    const bool axis = text.size() >= 3 && text[1] == '=' && (text[0] == 'x' || text[0] == 'y' || text[0] == 'z');
    const std::from_chars_result read = axis ? std::from_chars(text.data() + 2, end, p.index) : std::from_chars_result{};
    if (!axis || read.ec != std::errc() || read.ptr != end)
        throw Error("--slice: '" + text + "' is not AXIS=INDEX (x, y or z, an integer index: z=40)");
    p.axis = text[0] - 'x';
    return p;
}

std::vector<double> sliceValues(const RenderGrid& grid, const Camera& camera, const SlicePlane& plane) {
    std::vector<double> values(size_t(camera.width) * size_t(camera.height), std::numeric_limits<double>::quiet_NaN());
    const GridFrame frame(grid.indexToWorld);
    const DagTracer tracer(*grid.dag);
    const size_t a = size_t(plane.axis);
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height, 8), [&](const tbb::blocked_range<int>& rows) {
        size_t hint = 0;
        for (int py = rows.begin(); py != rows.end(); ++py)
            for (int px = 0; px < camera.width; ++px) {
                glm::dvec3 eye, dir;
                camera.pixelRay(px, py, eye, dir);
                const Ray ray = frame.toCellRay(eye, dir);
                if (ray.direction[a] == 0) continue;
                // The plane through the voxel centres: cell coordinate index + 0.5.
                const double t = (double(plane.index) + 0.5 - ray.origin[a]) / ray.direction[a];
                if (!(t >= 0) || !std::isfinite(t)) continue;
                std::array<int64_t, 3> voxel{};
                bool inRange = true;
                for (size_t k = 0; k < 3; ++k) {
                    const double c = k == a ? double(plane.index) : std::floor(ray.origin[k] + t * ray.direction[k]);
                    inRange = inRange && std::abs(c) < 4e18;  // else far outside any grid
                    voxel[k] = inRange ? int64_t(c) : 0;
                }
                if (!inRange) continue;
                if (const std::optional<uint64_t> e = tracer.find(voxel))
                    values[size_t(py) * size_t(camera.width) + size_t(px)] = grid.values ? valueAsDoubles(grid, *e, hint)[0] : 1.0;
            }
    });
    return values;
}

Projection renderSlice(const RenderGrid& grid, const Camera& camera, const SlicePlane& plane, std::optional<std::pair<double, double>> window) {
    const std::vector<double> values = sliceValues(grid, camera, plane);
    Projection out;
    std::tie(out.low, out.high) = window ? *window : automaticWindow(values);
    out.image = windowedGrey(values, camera.width, camera.height, out.low, out.high, false);
    return out;
}

} // namespace vdbdag::trace
