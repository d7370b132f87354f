// See TransferFunction.h.
#include "src/trace/TransferFunction.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "src/util/Error.h"

namespace vdbdag::trace {
namespace {

// Linear interpolation through points sorted by their first element.
template <size_t N>
std::array<double, N> interpolate(const std::vector<std::array<double, N>>& points, double v) {
    if (!(v > points.front()[0])) return points.front();
    if (!(v < points.back()[0])) return points.back();
    const auto upper = std::upper_bound(points.begin(), points.end(), v, [](double x, const std::array<double, N>& p) { return x < p[0]; });
    const std::array<double, N>& a = *(upper - 1);
    const std::array<double, N>& b = *upper;
    const double t = b[0] > a[0] ? (v - a[0]) / (b[0] - a[0]) : 0;
    std::array<double, N> out;
    for (size_t k = 0; k < N; ++k) out[k] = a[k] + (b[k] - a[k]) * t;
    return out;
}

double linearOfSrgb(double c) {
    c = std::clamp(c, 0.0, 1.0);
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

} // namespace

double TransferFunction::opacity(double v) const {
    if (std::isnan(v)) return 0;
    if (!opacityPoints.empty()) return interpolate(opacityPoints, v)[1];
    if (!(v > low)) return 0;
    const double t = std::min(1.0, (v - low) / (high > low ? high - low : 1));
    return kMaxOpacity * t * t;
}

glm::dvec3 TransferFunction::colour(double v) const {
    if (!colourPoints.empty()) {
        const std::array<double, 4> c = interpolate(colourPoints, std::isnan(v) ? low : v);
        return {c[1], c[2], c[3]};
    }
    const double t = std::clamp((v - low) / (high > low ? high - low : 1), 0.0, 1.0);
    const glm::dvec3 dark(0.45, 0.12, 0.06), ivory(0.95, 0.90, 0.78);  // linear light
    return dark + (ivory - dark) * std::sqrt(t);
}

TransferFunction readTransferFunction(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw Error(path + ": cannot open the transfer function file");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
        throw Error(path + ": not a JSON transfer function (" + std::string(e.what()) + ")");
    }
    if (j.is_array() && !j.empty()) j = j.front();
    if (!j.is_object() || !j.contains("RGBPoints")) throw Error(path + ": no \"RGBPoints\" (a ParaView colour-map preset is expected)");
    const auto numbers = [&](const char* key) {
        std::vector<double> out;
        const nlohmann::json& a = j.at(key);
        if (!a.is_array()) throw Error(path + ": \"" + key + "\" is not an array");
        for (const auto& x : a) {
            if (!x.is_number() || !std::isfinite(x.get<double>())) throw Error(path + ": \"" + key + "\" holds something that is not a finite number");
            out.push_back(x.get<double>());
        }
        if (out.size() % 4 || out.size() < 8) throw Error(path + ": \"" + key + "\" needs groups of 4 numbers, at least two");
        for (size_t i = 4; i < out.size(); i += 4)
            if (out[i] < out[i - 4]) throw Error(path + ": \"" + key + "\" values are not ascending");
        return out;
    };
    TransferFunction tf;
    const std::vector<double> rgb = numbers("RGBPoints");
    for (size_t i = 0; i < rgb.size(); i += 4) tf.colourPoints.push_back({rgb[i], linearOfSrgb(rgb[i + 1]), linearOfSrgb(rgb[i + 2]), linearOfSrgb(rgb[i + 3])});
    tf.low = tf.colourPoints.front()[0];
    tf.high = tf.colourPoints.back()[0];
    if (j.contains("Points")) {
        const std::vector<double> points = numbers("Points");
        for (size_t i = 0; i < points.size(); i += 4) tf.opacityPoints.push_back({points[i], kMaxOpacity * std::clamp(points[i + 1], 0.0, 1.0)});
    }
    return tf;
}

} // namespace vdbdag::trace
