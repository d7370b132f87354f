// See ScalarTolerance.h.
#include "src/attributes/ScalarTolerance.h"

#include <cmath>
#include <cstring>

#include <fmt/core.h>

namespace vdbdag::attributes {
namespace {

template <typename T>
ToleranceReport quantise(std::vector<uint8_t>& bytes, const ScalarTolerance& tol) {
    ToleranceReport report;
    report.tolerance = tol;
    const size_t n = bytes.size() / sizeof(T);
    report.entries = n;
    const double absStep = 2.0 * tol.bound;
    const double logStep = 2.0 * std::log2(1.0 + tol.bound);
    double sumAbs = 0, sumSq = 0;
    for (size_t i = 0; i < n; ++i) {
        T v;
        std::memcpy(&v, &bytes[i * sizeof(T)], sizeof(T));
        const double d = double(v);
        if (!std::isfinite(d) || d == 0.0) continue;  // NaN, Inf, +-0 stay exact
        double q;
        if (tol.mode == ScalarTolerance::Mode::Absolute) {
            q = std::nearbyint(d / absStep) * absStep;
        } else {
            const double e = std::nearbyint(std::log2(std::fabs(d)) / logStep) * logStep;
            q = std::copysign(std::exp2(e), d);
        }
        // A value rounded to zero keeps its sign (-0.0), so a level set's
        // inside/outside classification survives quantisation.
        const T stored = std::copysign(T(q), T(d));
        const double err = std::fabs(double(stored) - d);
        const double limit = tol.mode == ScalarTolerance::Mode::Absolute ? tol.bound : tol.bound * std::fabs(d);
        if (!std::isfinite(double(stored)) || !(err <= limit)) {
            ++report.keptExact;  // rounding would break the bound (or the sign of zero): keep it
            continue;
        }
        if (std::memcmp(&stored, &v, sizeof(T)) != 0) {
            ++report.changed;
            std::memcpy(&bytes[i * sizeof(T)], &stored, sizeof(T));
        }
        report.maxAbsError = std::max(report.maxAbsError, err);
        report.maxRelError = std::max(report.maxRelError, err / std::fabs(d));
        sumAbs += err;
        sumSq += err * err;
    }
    if (n) {
        report.meanAbsError = sumAbs / double(n);
        report.rmsError = std::sqrt(sumSq / double(n));
    }
    return report;
}

} // namespace

ToleranceReport applyScalarTolerance(std::vector<uint8_t>& values, ValueType type, const ScalarTolerance& tolerance) {
    if (tolerance.mode == ScalarTolerance::Mode::Exact) return {tolerance, values.size() / std::max(1u, valueSize(type))};
    if (type == ValueType::Float) return quantise<float>(values, tolerance);
    if (type == ValueType::Double) return quantise<double>(values, tolerance);
    ToleranceReport untouched;
    untouched.tolerance = tolerance;
    untouched.entries = values.size() / std::max(1u, valueSize(type));
    return untouched;
}

std::string describe(const ScalarTolerance& t) {
    switch (t.mode) {
        case ScalarTolerance::Mode::Exact: return "lossless";
        case ScalarTolerance::Mode::Absolute: return fmt::format("abs-error {:g}", t.bound);
        case ScalarTolerance::Mode::Relative: return fmt::format("rel-error {:g}", t.bound);
    }
    return "?";
}

} // namespace vdbdag::attributes
