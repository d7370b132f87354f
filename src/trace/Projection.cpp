// See Projection.h.
#include "src/trace/Projection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "src/trace/PixelSegments.h"

namespace vdbdag::trace {

std::vector<double> maximaAlongRays(const RenderGrid& grid, const Camera& camera) {
    std::vector<double> maxima(size_t(camera.width) * size_t(camera.height), std::numeric_limits<double>::quiet_NaN());
    forEachPixelSegment(grid, camera, [&](size_t pixel, const RayHit&, double v, double) {
        double& m = maxima[pixel];
        if (!std::isnan(v) && (std::isnan(m) || v > m)) m = v;
        return false;
    });
    return maxima;
}

std::pair<double, double> automaticWindow(const std::vector<double>& maxima) {
    std::vector<double> v;
    v.reserve(maxima.size());
    for (const double m : maxima)
        if (std::isfinite(m)) v.push_back(m);
    if (v.empty()) return {0, 1};
    std::sort(v.begin(), v.end());
    const double lo = v.front(), hi = v[std::min(v.size() - 1, size_t(double(v.size()) * 0.995))];
    if (!(hi > lo)) return {lo - 1, lo};  // one value: shown, white
    // Otsu's threshold over 256 bins of [lo, hi]: the split that maximises
    // the between-class variance (air against what is in it).
    constexpr int kBins = 256;
    std::array<double, kBins> count{};
    for (const double x : v) count[size_t(std::clamp(int((x - lo) / (hi - lo) * kBins), 0, kBins - 1))] += 1;
    double total = 0, sum = 0;
    for (int b = 0; b < kBins; ++b) total += count[size_t(b)], sum += b * count[size_t(b)];
    double weight0 = 0, sum0 = 0, bestVariance = -1;
    int threshold = 0;
    for (int b = 0; b < kBins - 1; ++b) {
        weight0 += count[size_t(b)];
        sum0 += b * count[size_t(b)];
        const double weight1 = total - weight0;
        if (weight0 == 0 || weight1 == 0) continue;
        const double mean0 = sum0 / weight0, mean1 = (sum - sum0) / weight1;
        const double variance = weight0 * weight1 * (mean0 - mean1) * (mean0 - mean1);
        if (variance > bestVariance) bestVariance = variance, threshold = b;
    }
    return {lo + (hi - lo) * double(threshold + 1) / kBins, hi};
}

std::pair<double, double> storedValueWindow(const RenderGrid& grid) {
    std::vector<double> sample;
    if (grid.values) {
        const uint64_t n = grid.values->entryCount, stride = std::max<uint64_t>(1, n >> 20);
        sample.reserve(size_t(n / stride + 1));
        size_t hint = 0;
        for (uint64_t e = 0; e < n; e += stride) sample.push_back(valueAsDoubles(grid, e, hint)[0]);
    }
    return automaticWindow(sample);
}

Projection renderMip(const RenderGrid& grid, const Camera& camera, std::optional<std::pair<double, double>> window) {
    const std::vector<double> maxima = maximaAlongRays(grid, camera);
    Projection out;
    std::tie(out.low, out.high) = window ? *window : automaticWindow(maxima);
    out.image = windowedGrey(maxima, camera.width, camera.height, out.low, out.high, true);
    return out;
}

Image windowedGrey(const std::vector<double>& values, int width, int height, double low, double high, bool lowTransparent) {
    Image image;
    image.resize(width, height);
    const double span = high > low ? high - low : 1;
    for (size_t i = 0; i < values.size(); ++i) {
        const double m = values[i];
        if (std::isnan(m) || (lowTransparent && !(m > low))) continue;  // nothing there, or at or below the window: transparent
        // Linear light whose sRGB code is proportional to the window position.
        const double g = std::clamp((m - low) / span, 0.0, 1.0);
        const float grey = float(g <= 0.04045 ? g / 12.92 : std::pow((g + 0.055) / 1.055, 2.4));
        for (int c = 0; c < 3; ++c) image.rgb[3 * i + size_t(c)] = grey;
        image.alpha[i] = 1;
    }
    return image;
}

} // namespace vdbdag::trace
