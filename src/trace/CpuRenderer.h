// Renders one grid of a .ssvdag with the CPU tracer (DagTracer): surfaces
// with Lambert shading (ONV normals when the grid has them, level-set
// gradient normals from point queries of the neighbours, otherwise the hit
// face), optional shadow rays, LOD cut-off; fog volumes by emission-absorption
// along every occupied box the ray crosses (the DAG skips empty space).
#pragma once
#include <optional>
#include <utility>

#include "src/trace/Camera.h"
#include "src/trace/Image.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/Shading.h"

namespace vdbdag::trace {

struct RenderStats {
    uint64_t primaryRays = 0, secondaryRays = 0;
    double milliseconds = 0;
    std::optional<std::pair<double, double>> window;  // --shading mip, volume, slice: the window used (given or chosen)
    std::optional<double> iso;                        // --shading iso: the surface's value (given or chosen)
};

Image renderCpu(const RenderGrid& grid, const Camera& camera, const RenderOptions& options, RenderStats* stats = nullptr);

} // namespace vdbdag::trace
