// libvdbdag_images.so: PNG scatter plots drawn with OpenImageIO's ImageBufAlgo;
// see PlotWriter.h and ImageModule.h.
#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>

#include <fmt/core.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "vdb_bridge/image_module/ImageModule.h"

namespace {

using vdbdag::bridge::PlotSeries;
using vdbdag::bridge::PlotSpec;

struct LogAxis {
    double lo, hi;  // log10 range
    int from, to;   // pixel range
    int map(double v) const { return int(std::lround(from + (std::log10(v) - lo) / (hi - lo) * (to - from))); }
};

LogAxis axisFor(std::vector<double> values, int from, int to) {
    values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !(v > 0) || !std::isfinite(v); }), values.end());
    double lo = 0, hi = 1;
    if (!values.empty()) {
        lo = std::floor(std::log10(*std::min_element(values.begin(), values.end())));
        hi = std::ceil(std::log10(*std::max_element(values.begin(), values.end())));
        if (hi <= lo) hi = lo + 1;
    }
    return {lo, hi, from, to};
}

// OpenImageIO looks for its own default font; point it at DejaVu Sans
// (fonts-dejavu-core, installed by scripts/setup.sh) when it is there.
std::string fontPath() {
    const char* candidates[] = {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "/usr/share/fonts/TTF/DejaVuSans.ttf"};
    for (const char* c : candidates)
        if (std::filesystem::exists(c)) return c;
    return "";
}

void text(OIIO::ImageBuf& image, int x, int y, const std::string& s, int size, OIIO::ImageBufAlgo::TextAlignX align = OIIO::ImageBufAlgo::TextAlignX::Left) {
    static const std::string font = fontPath();
    const float black[3] = {0, 0, 0};
    OIIO::ImageBufAlgo::render_text(image, x, y, s, size, font, black, align);
}

bool writeScatterPlot(const std::string& path, const std::vector<PlotSeries>& series, const PlotSpec& spec, std::string& error) {
    const int W = spec.width, H = spec.height, left = 110, right = W - 230, top = 50, bottom = H - 70;
    OIIO::ImageBuf image(OIIO::ImageSpec(W, H, 3, OIIO::TypeDesc::UINT8));
    const float white[3] = {1, 1, 1}, black[3] = {0, 0, 0}, grey[3] = {0.85f, 0.85f, 0.85f};
    OIIO::ImageBufAlgo::fill(image, white);

    std::vector<double> xs, ys;
    for (const PlotSeries& s : series) {
        xs.insert(xs.end(), s.x.begin(), s.x.end());
        ys.insert(ys.end(), s.y.begin(), s.y.end());
    }
    const LogAxis ax = axisFor(xs, left, right);
    LogAxis ay = axisFor(ys, bottom - 30, top);  // the bottom 30 pixels hold the "exact" floor
    const int floorY = bottom - 10;
    auto yPixel = [&](double v) { return v > 0 && std::isfinite(v) ? ay.map(v) : floorY; };

    // Grid lines and decade labels.
    for (int e = int(ax.lo); e <= int(ax.hi); ++e) {
        const int x = ax.map(std::pow(10.0, e));
        OIIO::ImageBufAlgo::render_line(image, x, top, x, bottom, grey);
        text(image, x, bottom + 22, fmt::format("1e{}", e), 14, OIIO::ImageBufAlgo::TextAlignX::Center);
    }
    for (int e = int(ay.lo); e <= int(ay.hi); ++e) {
        const int y = ay.map(std::pow(10.0, e));
        OIIO::ImageBufAlgo::render_line(image, left, y, right, y, grey);
        text(image, left - 8, y + 5, fmt::format("1e{}", e), 14, OIIO::ImageBufAlgo::TextAlignX::Right);
    }
    OIIO::ImageBufAlgo::render_line(image, left, floorY, right, floorY, grey);
    text(image, left - 8, floorY + 5, "exact", 14, OIIO::ImageBufAlgo::TextAlignX::Right);
    OIIO::ImageBufAlgo::render_box(image, left, top, right, bottom, black);
    text(image, (left + right) / 2, 30, spec.title, 18, OIIO::ImageBufAlgo::TextAlignX::Center);
    text(image, (left + right) / 2, H - 20, spec.xLabel, 16, OIIO::ImageBufAlgo::TextAlignX::Center);
    text(image, 10, top - 15, spec.yLabel, 16);

    // The Pareto front: joined in x order and circled.
    std::vector<std::pair<int, int>> frontPixels;
    for (auto [si, pi] : spec.front)
        if (si < series.size() && pi < series[si].x.size() && series[si].x[pi] > 0)
            frontPixels.push_back({ax.map(series[si].x[pi]), yPixel(series[si].y[pi])});
    std::sort(frontPixels.begin(), frontPixels.end());
    for (size_t i = 1; i < frontPixels.size(); ++i)
        OIIO::ImageBufAlgo::render_line(image, frontPixels[i - 1].first, frontPixels[i - 1].second, frontPixels[i].first, frontPixels[i].second, black);
    for (auto [x, y] : frontPixels) OIIO::ImageBufAlgo::render_box(image, x - 7, y - 7, x + 7, y + 7, black);

    // Points and legend.
    for (size_t si = 0; si < series.size(); ++si) {
        const PlotSeries& s = series[si];
        const float* c = s.colour.data();
        for (size_t i = 0; i < s.x.size(); ++i) {
            if (!(s.x[i] > 0) || !std::isfinite(s.x[i])) continue;
            const int x = ax.map(s.x[i]), y = yPixel(s.y[i]);
            OIIO::ImageBufAlgo::render_box(image, x - 4, y - 4, x + 4, y + 4, OIIO::cspan<float>(c, 3), true);
        }
        const int ly = top + 10 + int(si) * 22;
        OIIO::ImageBufAlgo::render_box(image, right + 15, ly - 5, right + 25, ly + 5, OIIO::cspan<float>(c, 3), true);
        text(image, right + 32, ly + 5, s.label, 14);
    }
    const int ly = top + 10 + int(series.size()) * 22;
    OIIO::ImageBufAlgo::render_box(image, right + 13, ly - 7, right + 27, ly + 7, black);
    text(image, right + 32, ly + 5, "Pareto front", 14);

    if (image.write(path)) return true;
    error = "cannot write the plot: " + image.geterror();
    return false;
}

} // namespace

extern "C" __attribute__((visibility("default"))) bool vdbdag_images_write_plot(const char* path, const std::vector<PlotSeries>& series,
                                                                                 const PlotSpec& spec, std::string& error) {
    static_assert(std::is_same_v<decltype(vdbdag_images_write_plot), vdbdag::bridge::image_module::WritePlotFn>);
    try {
        return writeScatterPlot(path, series, spec, error);
    } catch (const std::exception& e) {
        error = e.what();
        return false;
    }
}
