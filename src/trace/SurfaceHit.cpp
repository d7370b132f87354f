// First surface along a ray; see SurfaceHit.h.
#include "src/trace/SurfaceHit.h"

#include "src/trace/DagWalk.h"

namespace vdbdag::trace {

RayHit firstSurfaceHit(const RenderGrid& grid, const DagTracer& tracer, const Ray& ray, double ignoreBefore) {
    if (!grid.levelSet) {
        Ray clipped = ray;
        clipped.tMin = std::max(ray.tMin, ignoreBefore);
        return tracer.trace(clipped);
    }
    RayHit found;
    if (grid.inside) {  // one bit per entry (InsideBits.h); leaves with no inside voxel are crossed as empty space
        const InsideBits& inside = *grid.inside;
        detail::walkRay<false>(
            tracer.dag(), tracer.options(), tracer.box(), ray,
            [&](const RayHit& box, double) {
                if (box.t < ignoreBefore || !inside.inside(box.attribute)) return false;
                found = box;
                return true;
            },
            [&](uint64_t first, unsigned count) { return inside.anyInside(first, count); });
        return found;
    }
    size_t blockHint = 0;
    detail::walkRay<false>(tracer.dag(), tracer.options(), tracer.box(), ray, [&](const RayHit& box, double) {
        if (box.t < ignoreBefore || !(valueAsDoubles(grid, box.attribute, blockHint)[0] <= 0)) return false;
        found = box;
        return true;
    });
    return found;
}

} // namespace vdbdag::trace
