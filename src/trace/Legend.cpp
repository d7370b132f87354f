// See Legend.h.
#include "src/trace/Legend.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <fmt/core.h>

#include "src/trace/Shading.h"
#include "src/trace/VolumeRender.h"

namespace vdbdag::trace {
namespace {

// 3x5 glyphs, one row per 3 bits (top row first, bit 2 the left column).
std::array<uint8_t, 5> glyph(char c) {
    switch (c) {
        case '0': return {7, 5, 5, 5, 7};
        case '1': return {2, 6, 2, 2, 7};
        case '2': return {7, 1, 7, 4, 7};
        case '3': return {7, 1, 7, 1, 7};
        case '4': return {5, 5, 7, 1, 1};
        case '5': return {7, 4, 7, 1, 7};
        case '6': return {7, 4, 7, 5, 7};
        case '7': return {7, 1, 1, 2, 2};
        case '8': return {7, 5, 7, 5, 7};
        case '9': return {7, 5, 7, 1, 7};
        case '-': return {0, 0, 7, 0, 0};
        case '+': return {0, 2, 7, 2, 0};
        case '.': return {0, 0, 0, 0, 2};
        case 'e': return {0, 7, 7, 4, 7};
        // The letters of the units valueUnits names.
        case 'B': return {6, 5, 6, 5, 6};
        case 'H': return {5, 5, 7, 5, 5};
        case 'U': return {5, 5, 5, 5, 7};
        case 'q': return {0, 7, 5, 7, 1};
        case 'g': return {0, 7, 5, 7, 3};
        case 'm': return {0, 7, 7, 5, 5};
        case 'l': return {2, 2, 2, 2, 2};
        case 'c': return {0, 7, 4, 4, 7};
        case 'o': return {0, 7, 5, 5, 7};
        case 'u': return {0, 5, 5, 5, 7};
        case 'n': return {0, 6, 5, 5, 5};
        case 't': return {2, 7, 2, 2, 3};
        case 's': return {0, 3, 6, 1, 6};
        case '/': return {1, 1, 2, 4, 4};
        default: return {0, 0, 0, 0, 0};
    }
}

void setPixel(Image& image, int x, int y, const glm::dvec3& c) {
    if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
    const size_t i = size_t(y) * size_t(image.width) + size_t(x);
    for (int a = 0; a < 3; ++a) image.rgb[3 * i + size_t(a)] = float(c[a]);
    image.alpha[i] = 1;
}

// `text` with its right edge at `right` and its top at `top`, glyphs scaled by `s`.
void drawText(Image& image, const std::string& text, int right, int top, int s) {
    const int advance = 4 * s;
    int x = right - int(text.size()) * advance + s;
    for (const char c : text) {
        const std::array<uint8_t, 5> g = glyph(c);
        for (int row = 0; row < 5; ++row)
            for (int col = 0; col < 3; ++col)
                if (g[size_t(row)] >> (2 - col) & 1)
                    for (int dy = 0; dy < s; ++dy)
                        for (int dx = 0; dx < s; ++dx) setPixel(image, x + col * s + dx, top + row * s + dy, glm::dvec3(1));
        x += advance;
    }
}

glm::dvec3 grey(double g) {
    g = std::clamp(g, 0.0, 1.0);
    return glm::dvec3(g <= 0.04045 ? g / 12.92 : std::pow((g + 0.055) / 1.055, 2.4));  // sRGB code proportional to g, as Projection's
}

} // namespace

std::optional<LegendScale> legendScale(const RenderGrid& grid, const std::optional<std::pair<double, double>>& window, const TransferFunction* transfer) {
    if ((grid.mip || grid.slice) && window) {
        const double lo = window->first, hi = window->second;
        return LegendScale{lo, hi, [lo, hi](double v) { return grey((v - lo) / (hi > lo ? hi - lo : 1)); }, {}};
    }
    if (grid.volume && window) {
        const TransferFunction tf = transfer ? *transfer : TransferFunction{window->first, window->second, {}, {}};
        return LegendScale{tf.low, tf.high, [tf](double v) { return tf.colour(v); }, {}};
    }
    if (!grid.mip && !grid.slice && !grid.volume && !grid.iso && !grid.labels && !grid.fog && !grid.levelSet &&
        grid.colouring == ValueColouring::Scalar) {
        const double lo = grid.valueMin, hi = grid.valueMax;
        return LegendScale{lo, hi, [lo, hi](double v) { return coolToWarm((v - lo) / (hi - lo)); }, {}};
    }
    return std::nullopt;
}

std::string valueUnits(const std::vector<std::pair<std::string, std::string>>& metadata) {
    const auto find = [&](const char* name) -> std::string {
        for (const auto& [key, value] : metadata)
            if (key == name) return value;
        return {};
    };
    // DICOM's Units (0054,1001) for PET, then Rescale Type (0028,1054), then
    // a CT's Hounsfield units.
    const std::string units = find("dicom_Units");
    if (units == "BQML") return "Bq/ml";
    if (units == "CNTS") return "counts";
    if (units == "GML") return "g/ml";
    if (units == "HU") return "HU";
    const std::string rescale = find("dicom_RescaleType");
    if (rescale == "HU") return "HU";
    if (find("dicom_Modality") == "CT" && (rescale.empty() || rescale == "US")) return "HU";
    return {};
}

void drawLegend(Image& image, const LegendScale& scale) {
    if (image.width < 64 || image.height < 48) return;
    const int s = std::max(1, image.height / 240);          // glyph scale
    const int margin = std::max(4, image.width / 80);
    const int barWidth = std::max(6, image.width / 60);
    const int textHeight = 5 * s;
    const int top = margin + textHeight + 2 * s, bottom = image.height - margin - textHeight - 2 * s;  // the bar's rows [top, bottom)
    const int right = image.width - margin, left = right - barWidth;
    if (bottom - top < 8) return;
    for (int y = top; y < bottom; ++y) {
        const double t = 1 - (double(y - top) + 0.5) / double(bottom - top);
        const glm::dvec3 c = scale.colour(scale.low + t * (scale.high - scale.low));
        for (int x = left; x < right; ++x) setPixel(image, x, y, c);
    }
    drawText(image, fmt::format("{:.4g}", scale.high) + (scale.units.empty() ? "" : " " + scale.units), right, margin, s);
    drawText(image, fmt::format("{:.4g}", scale.low), right, bottom + 2 * s, s);
}

} // namespace vdbdag::trace
