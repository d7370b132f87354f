// Every pixel's ray through a grid's occupied boxes (DagTracer::forEachSegment),
// rows of pixels in parallel: the walk shared by the renderings that look at
// values along the whole ray (Projection.h, LabelRender.h, IsoSurface.h).
#pragma once
#include <cstddef>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "src/trace/Camera.h"
#include "src/trace/DagTracer.h"
#include "src/trace/RenderGrid.h"

namespace vdbdag::trace {

// visit(pixel, box, value, tLeave) for each box along pixel's ray, in
// order, with the box's scalar value (1 when the grid stores none) and the
// ray parameter where the ray leaves it; returning true ends that ray.
// Calls for different pixels may run at once; one pixel's all come from
// one thread.
template <typename Visit>
void forEachPixelSegment(const RenderGrid& grid, const Camera& camera, Visit&& visit) {
    const GridFrame frame(grid.indexToWorld);
    const DagTracer tracer(*grid.dag);
    tbb::parallel_for(tbb::blocked_range<int>(0, camera.height, 4), [&](const tbb::blocked_range<int>& rows) {
        size_t hint = 0;
        for (int py = rows.begin(); py != rows.end(); ++py)
            for (int px = 0; px < camera.width; ++px) {
                glm::dvec3 eye, dir;
                camera.pixelRay(px, py, eye, dir);
                const size_t pixel = size_t(py) * size_t(camera.width) + size_t(px);
                tracer.forEachSegment(frame.toCellRay(eye, dir), [&](const RayHit& box, double tLeave) {
                    return visit(pixel, box, grid.values ? valueAsDoubles(grid, box.attribute, hint)[0] : 1.0, tLeave);
                });
            }
    });
}

} // namespace vdbdag::trace
