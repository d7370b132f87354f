// Scatter plots for `vdbdag bench` (error against size, error against time),
// drawn with OpenImageIO's ImageBufAlgo (in libvdbdag_images.so) and written
// as PNG: log-log axes, one colour per family of points, the Pareto front
// circled and joined.
#pragma once
#include <array>
#include <string>
#include <vector>

namespace vdbdag::bridge {

struct PlotSeries {
    std::string label;
    std::vector<double> x, y;
    std::array<float, 3> colour{0, 0, 0};
};

struct PlotSpec {
    std::string title, xLabel, yLabel;
    // Points on the Pareto front, as (series, index) pairs.
    std::vector<std::pair<size_t, size_t>> front;
    int width = 960, height = 640;
};

// y values <= 0 (exact) are drawn on a floor line labelled "exact".
void writeScatterPlot(const std::string& path, const std::vector<PlotSeries>& series, const PlotSpec& spec);

} // namespace vdbdag::bridge
