// See ValueRange.h.
#include "src/attributes/ValueRange.h"

#include <cmath>
#include <cstring>
#include <type_traits>

namespace vdbdag::attributes {
namespace {

template <typename T>
T load(const uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return v;
}

// -1, 0 or 1: a before, equal to or after b; -0.0 before +0.0.
template <typename T>
int compareScalar(const uint8_t* a, const uint8_t* b) {
    const T x = load<T>(a), y = load<T>(b);
    if (x < y) return -1;
    if (y < x) return 1;
    if constexpr (std::is_floating_point_v<T>) {
        const bool nx = std::signbit(x), ny = std::signbit(y);  // equal: both zeros, or the same value
        return nx == ny ? 0 : nx ? -1 : 1;
    }
    return 0;
}

template <typename T>
bool hasNan(const uint8_t* p, unsigned n) {
    if constexpr (std::is_floating_point_v<T>) {
        for (unsigned i = 0; i < n; ++i)
            if (std::isnan(load<T>(p + i * sizeof(T)))) return true;
    }
    return false;
}

// The component type's comparison over `n` components, lexicographically.
template <typename T>
int compareValues(const uint8_t* a, const uint8_t* b, unsigned n) {
    for (unsigned i = 0; i < n; ++i)
        if (const int r = compareScalar<T>(a + i * sizeof(T), b + i * sizeof(T))) return r;
    return 0;
}

template <typename T>
void addAll(ValueRange& range, std::span<const uint8_t> values, unsigned n) {
    const size_t vs = n * sizeof(T);
    for (size_t at = 0; at + vs <= values.size(); at += vs) {
        const uint8_t* v = values.data() + at;
        if (hasNan<T>(v, n)) continue;
        if (range.min.empty()) {
            range.min.assign(v, v + vs);
            range.max.assign(v, v + vs);
            continue;
        }
        if (compareValues<T>(v, range.min.data(), n) < 0) std::memcpy(range.min.data(), v, vs);
        if (compareValues<T>(range.max.data(), v, n) < 0) std::memcpy(range.max.data(), v, vs);
    }
}

} // namespace

void ValueRange::add(ValueType type, std::span<const uint8_t> values) {
    switch (type) {
    case ValueType::Float: return addAll<float>(*this, values, 1);
    case ValueType::Double: return addAll<double>(*this, values, 1);
    case ValueType::Int32: return addAll<int32_t>(*this, values, 1);
    case ValueType::Int64: return addAll<int64_t>(*this, values, 1);
    case ValueType::Bool: return addAll<uint8_t>(*this, values, 1);
    case ValueType::Mask: return;
    case ValueType::Vec3S: return addAll<float>(*this, values, 3);
    case ValueType::Vec3D: return addAll<double>(*this, values, 3);
    case ValueType::Vec3I: return addAll<int32_t>(*this, values, 3);
    }
}

void ValueRange::merge(ValueType type, const ValueRange& other) {
    if (other.empty()) return;
    add(type, other.min);
    add(type, other.max);
}

} // namespace vdbdag::attributes
