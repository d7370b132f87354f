// A raw value (GridRecord's valueSize bytes) as doubles: scalars in [0],
// vectors in [0..2]. Shared by the renderers' shading and `info`'s report.
#pragma once
#include <array>
#include <cstdint>
#include <cstring>

#include "src/volume/GridRecord.h"

namespace vdbdag {

// Doubles a value of `type` has: 1 for scalars and bool, 3 for vectors, 0 for masks.
inline unsigned valueComponents(ValueType type) {
    switch (type) {
    case ValueType::Mask: return 0;
    case ValueType::Vec3S:
    case ValueType::Vec3D:
    case ValueType::Vec3I: return 3;
    default: return 1;
    }
}

// `bytes` must hold valueSize(type) bytes.
inline std::array<double, 3> valueAsDoubles(ValueType type, const uint8_t* bytes) {
    std::array<double, 3> out{0, 0, 0};
    switch (type) {
    case ValueType::Float: { float f; std::memcpy(&f, bytes, 4); out[0] = f; break; }
    case ValueType::Double: std::memcpy(&out[0], bytes, 8); break;
    case ValueType::Int32: { int32_t i; std::memcpy(&i, bytes, 4); out[0] = i; break; }
    case ValueType::Int64: { int64_t i; std::memcpy(&i, bytes, 8); out[0] = double(i); break; }
    case ValueType::Bool: out[0] = bytes[0] ? 1 : 0; break;
    case ValueType::Mask: break;
    case ValueType::Vec3S: { float f[3]; std::memcpy(f, bytes, 12); out = {f[0], f[1], f[2]}; break; }
    case ValueType::Vec3D: std::memcpy(out.data(), bytes, 24); break;
    case ValueType::Vec3I: { int32_t i[3]; std::memcpy(i, bytes, 12); out = {double(i[0]), double(i[1]), double(i[2])}; break; }
    }
    return out;
}

} // namespace vdbdag
