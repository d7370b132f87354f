// See ValueGradient.h.
#include "src/trace/ValueGradient.h"

#include <cmath>

namespace vdbdag::trace {

std::optional<glm::dvec3> valueGradient(const RenderGrid& grid, const DagTracer& tracer, const std::array<int64_t, 3>& voxel, double centre) {
    glm::dvec3 g(0);
    for (int a = 0; a < 3; ++a) {
        std::array<int64_t, 3> plus = voxel, minus = voxel;
        ++plus[size_t(a)];
        --minus[size_t(a)];
        const auto p = tracer.find(plus), m = tracer.find(minus);
        if (p && m) g[a] = (valueAsDoubles(grid, *p)[0] - valueAsDoubles(grid, *m)[0]) * 0.5;
        else if (p) g[a] = valueAsDoubles(grid, *p)[0] - centre;
        else if (m) g[a] = centre - valueAsDoubles(grid, *m)[0];
    }
    const double len = glm::length(g);
    if (!(len > 0) || !std::isfinite(len)) return std::nullopt;
    return g / len;
}

} // namespace vdbdag::trace
