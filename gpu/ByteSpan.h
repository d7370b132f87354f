// Byte views of host arrays for upload (DeviceArray takes bytes): a
// vector's storage as bytes, and a 16-byte zero block standing in for an
// empty section so that every device address stays valid.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

namespace vdbdag::gpu {

template <class T>
std::span<const uint8_t> bytesOf(const std::vector<T>& v) {
    return {reinterpret_cast<const uint8_t*>(v.data()), v.size() * sizeof(T)};
}

inline std::span<const uint8_t> orZeros(std::span<const uint8_t> bytes) {
    static const uint8_t zeros[16] = {};
    return bytes.empty() ? std::span<const uint8_t>(zeros, 16) : bytes;
}

} // namespace vdbdag::gpu
