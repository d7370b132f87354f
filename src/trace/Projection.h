// Maximum intensity projection (`render --shading mip`): each pixel shows
// the largest value its ray meets in the grid's occupied boxes (the DAG
// skips empty space; a dense scan's air is not empty, it is dark). The
// display window maps [low, high] to black..white; values at or below low
// leave the pixel transparent, so a CT's air does not paint the volume's box.
// Without a window given, low is Otsu's threshold of the pixels' maxima (air
// against tissue) and high their 99.5th percentile. The Vulkan tracer finds
// the same maxima (trace.comp, MIP) and windows them with these functions.
#pragma once
#include <optional>
#include <utility>
#include <vector>

#include "src/trace/Camera.h"
#include "src/trace/Image.h"
#include "src/trace/RenderGrid.h"

namespace vdbdag::trace {

// Per pixel, row-major: the largest scalar value along the ray; NaN where
// the ray meets no occupied box.
std::vector<double> maximaAlongRays(const RenderGrid& grid, const Camera& camera);

// The window chosen from maxima (Otsu's threshold, the 99.5th percentile).
std::pair<double, double> automaticWindow(const std::vector<double>& maxima);
// automaticWindow of the grid's stored scalar values (a sample of at most
// 2^20 entries): air against tissue, for isosurfaces and volumes.
std::pair<double, double> storedValueWindow(const RenderGrid& grid);

struct Projection {
    Image image;
    double low = 0, high = 1;  // the window used
};

// Per-pixel values (NaN: nothing there) through the window [low, high] as
// grey levels whose sRGB codes are proportional to the window position;
// values at or below low are transparent when `lowTransparent`, else black.
Image windowedGrey(const std::vector<double>& values, int width, int height, double low, double high, bool lowTransparent);
Projection renderMip(const RenderGrid& grid, const Camera& camera, std::optional<std::pair<double, double>> window = std::nullopt);

} // namespace vdbdag::trace
