// See ScalarTolerance.h.
#include "src/attributes/ScalarTolerance.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/core.h>

namespace vdbdag::attributes {

ScalarQuantizer::ScalarQuantizer(ValueType type, const ScalarTolerance& tolerance) : type_(type) { report_.tolerance = tolerance; }

template <typename T>
void ScalarQuantizer::quantise(std::span<uint8_t> bytes) {
    const ScalarTolerance& tol = report_.tolerance;
    const size_t n = bytes.size() / sizeof(T);
    const double absStep = 2.0 * tol.bound;
    const double logStep = 2.0 * std::log2(1.0 + tol.bound);
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
            ++report_.keptExact;  // rounding would break the bound (or the sign of zero): keep it
            continue;
        }
        if (std::memcmp(&stored, &v, sizeof(T)) != 0) {
            ++report_.changed;
            std::memcpy(&bytes[i * sizeof(T)], &stored, sizeof(T));
        }
        report_.maxAbsError = std::max(report_.maxAbsError, err);
        report_.maxRelError = std::max(report_.maxRelError, err / std::fabs(d));
        sumAbs_ += err;
        sumSq_ += err * err;
    }
}

// Integers (absolute bound only): each value to the nearest multiple of
// s = 2 floor(E) + 1, so the error is at most floor(E) and the values share
// the step s, which the value coder divides out (ContextChannel.h). A value
// whose multiple would leave the type's range stays exact.
__extension__ typedef __int128 Int128;  // GCC's and clang's 128-bit integer (not ISO C++: -Wpedantic)

template <typename T>
void ScalarQuantizer::quantiseIntegers(std::span<uint8_t> bytes) {
    const ScalarTolerance& tol = report_.tolerance;
    if (tol.mode != ScalarTolerance::Mode::Absolute || !(tol.bound >= 1)) return;
    const Int128 half = Int128(std::min(tol.bound, 1e15)), s = 2 * half + 1;
    const size_t n = bytes.size() / sizeof(T);
    for (size_t i = 0; i < n; ++i) {
        T v;
        std::memcpy(&v, &bytes[i * sizeof(T)], sizeof(T));
        Int128 r = Int128(v) % s;
        if (r < 0) r += s;
        Int128 q = Int128(v) - r;
        if (r > half) q += s;
        if (q < Int128(std::numeric_limits<T>::min()) || q > Int128(std::numeric_limits<T>::max())) {
            ++report_.keptExact;
            continue;
        }
        const T stored = T(q);
        const double err = double(q > Int128(v) ? q - Int128(v) : Int128(v) - q);
        if (stored != v) {
            ++report_.changed;
            std::memcpy(&bytes[i * sizeof(T)], &stored, sizeof(T));
        }
        report_.maxAbsError = std::max(report_.maxAbsError, err);
        if (v != 0) report_.maxRelError = std::max(report_.maxRelError, err / std::fabs(double(v)));
        sumAbs_ += err;
        sumSq_ += err * err;
    }
}

void ScalarQuantizer::apply(std::span<uint8_t> values) {
    report_.entries += values.size() / std::max(1u, valueSize(type_));
    if (report_.tolerance.mode == ScalarTolerance::Mode::Exact) return;
    if (type_ == ValueType::Float) quantise<float>(values);
    else if (type_ == ValueType::Double) quantise<double>(values);
    else if (type_ == ValueType::Int32) quantiseIntegers<int32_t>(values);
    else if (type_ == ValueType::Int64) quantiseIntegers<int64_t>(values);
}

ToleranceReport ScalarQuantizer::finish() const {
    ToleranceReport report = report_;
    if (report.entries && (type_ == ValueType::Float || type_ == ValueType::Double || type_ == ValueType::Int32 || type_ == ValueType::Int64) &&
        report.tolerance.mode != ScalarTolerance::Mode::Exact) {
        report.meanAbsError = sumAbs_ / double(report.entries);
        report.rmsError = std::sqrt(sumSq_ / double(report.entries));
    }
    return report;
}

ToleranceReport applyScalarTolerance(std::vector<uint8_t>& values, ValueType type, const ScalarTolerance& tolerance) {
    ScalarQuantizer quantizer(type, tolerance);
    quantizer.apply(values);
    return quantizer.finish();
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
