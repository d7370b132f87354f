// Little-endian byte writer and bounds-checked reader used by every section
// serialiser. The reader throws vdbdag::Error on any read past the end, so a
// truncated section can never be read out of bounds.
#pragma once
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "src/util/Error.h"

namespace vdbdag::format {

class ByteWriter {
public:
    template <typename T>
    void put(T value) {
        static_assert(std::is_trivially_copyable_v<T>);
        // Every supported target is little-endian (checked in ByteIO.cpp).
        // resize + memcpy rather than insert(p, p + n): same speed, and no
        // GCC 12 -Wstringop-overflow false positive.
        const size_t at = bytes_.size();
        bytes_.resize(at + sizeof(T));
        std::memcpy(bytes_.data() + at, &value, sizeof(T));
    }
    void putBytes(std::span<const uint8_t> data) { bytes_.insert(bytes_.end(), data.begin(), data.end()); }
    void putString(const std::string& s) {
        put<uint32_t>(uint32_t(s.size()));
        bytes_.insert(bytes_.end(), s.begin(), s.end());
    }
    template <typename T>
    void putArray(std::span<const T> values) {
        const auto* p = reinterpret_cast<const uint8_t*>(values.data());
        bytes_.insert(bytes_.end(), p, p + values.size_bytes());
    }
    std::vector<uint8_t>& bytes() { return bytes_; }
    std::vector<uint8_t> take() { return std::move(bytes_); }

private:
    std::vector<uint8_t> bytes_;
};

class ByteReader {
public:
    ByteReader(std::span<const uint8_t> data, std::string what) : data_(data), what_(std::move(what)) {}

    template <typename T>
    T get() {
        static_assert(std::is_trivially_copyable_v<T>);
        need(sizeof(T));
        T value;
        std::memcpy(&value, data_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        return value;
    }
    std::string getString(size_t maxLength = 1u << 20) {
        const uint32_t n = get<uint32_t>();
        if (n > maxLength) fail("string length " + std::to_string(n) + " is implausible");
        need(n);
        std::string s(reinterpret_cast<const char*>(data_.data() + pos_), n);
        pos_ += n;
        return s;
    }
    // Reads `count` elements; checks the bytes exist before allocating.
    template <typename T>
    std::vector<T> getArray(uint64_t count) {
        if (count > remaining() / sizeof(T)) fail("array of " + std::to_string(count) + " elements runs past the end");
        std::vector<T> values(count);
        if (count != 0) std::memcpy(values.data(), data_.data() + pos_, count * sizeof(T));  // data() may be null when empty
        pos_ += count * sizeof(T);
        return values;
    }
    void skip(size_t n) {
        need(n);
        pos_ += n;
    }
    size_t remaining() const { return data_.size() - pos_; }
    size_t position() const { return pos_; }
    [[noreturn]] void fail(const std::string& why) const { throw Error(what_ + ": " + why); }
    void expectEnd() const {
        if (remaining() != 0) fail(std::to_string(remaining()) + " unexpected trailing bytes");
    }

private:
    void need(size_t n) const {
        if (n > remaining()) fail("truncated (needs " + std::to_string(n) + " more bytes at offset " + std::to_string(pos_) + ")");
    }
    std::span<const uint8_t> data_;
    std::string what_;
    size_t pos_ = 0;
};

} // namespace vdbdag::format
