// A colour bar in a rendered image (`render --legend`): the colours a value
// takes from `low` (bottom) to `high` (top), drawn opaque in the image's
// right margin with both numbers in a small built-in font, so a picture of
// values says what its colours mean. For value shading (the cool-to-warm
// map over the grid's range), maximum intensity projections and slices (the
// grey window) and volume rendering (the transfer function's colours).
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "src/trace/Image.h"
#include "src/trace/RenderGrid.h"
#include "src/trace/TransferFunction.h"

namespace vdbdag::trace {

struct LegendScale {
    double low = 0, high = 1;
    std::function<glm::dvec3(double value)> colour;  // linear RGB of a value
    std::string units;  // drawn after the high value ("HU", "Bq/ml"); empty: none
};

// The units of a grid's values from its metadata (name, value as text):
// DICOM's Units for a PET (BQML -> Bq/ml, CNTS -> counts, GML -> g/ml),
// Rescale Type HU, or HU for a CT; empty when nothing says.
std::string valueUnits(const std::vector<std::pair<std::string, std::string>>& metadata);

// The scale of what `grid` is shown as with `window` (RenderStats::window:
// mip, slice, volume); nothing for shadings without one value map (fog,
// surfaces, labels, isosurfaces, colours and vectors). A volume's colours
// are `transfer`'s when given (a --tf file), else the ramp's over `window`.
std::optional<LegendScale> legendScale(const RenderGrid& grid, const std::optional<std::pair<double, double>>& window,
                                       const TransferFunction* transfer = nullptr);

// Draws the bar and its two numbers; images narrower than 64 or lower than
// 48 pixels are left as they are.
void drawLegend(Image& image, const LegendScale& scale);

} // namespace vdbdag::trace
