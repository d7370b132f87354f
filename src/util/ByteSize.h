// Memory sizes as users write them ("512M", "4G", "1048576"): a positive
// whole number of bytes with an optional unit k/K, m/M, g/G, t/T (powers of
// 1024; "KB", "KiB" and "kib" read the same), at most 2^60. "-1", 23-digit
// numbers and 0 (which options read as "the default") are refused.
#pragma once
#include <cctype>
#include <cstdint>
#include <string>

#include "src/util/Error.h"

namespace vdbdag {

// Throws vdbdag::Error saying why `text` is not a size.
inline uint64_t parseByteSize(const std::string& text) {
    const std::string refuse = "'" + text + "' is not a size: give a positive number of bytes, e.g. 512M or 4G";
    size_t i = 0;
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    const size_t digits = i;
    uint64_t value = 0;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) {
        if (value > (uint64_t(1) << 60) / 10) throw Error(refuse + " (at most 2^60 bytes)");
        value = value * 10 + uint64_t(text[i++] - '0');
    }
    if (i == digits) throw Error(refuse);
    std::string unit;
    for (; i < text.size(); ++i)
        if (!std::isspace(static_cast<unsigned char>(text[i]))) unit += char(std::tolower(static_cast<unsigned char>(text[i])));
    unsigned shift = 0;
    if (unit == "" || unit == "b") shift = 0;
    else if (unit == "k" || unit == "kb" || unit == "kib") shift = 10;
    else if (unit == "m" || unit == "mb" || unit == "mib") shift = 20;
    else if (unit == "g" || unit == "gb" || unit == "gib") shift = 30;
    else if (unit == "t" || unit == "tb" || unit == "tib") shift = 40;
    else throw Error(refuse + " (units: K, M, G, T)");
    if (value == 0) throw Error(refuse + " (0 is not a size; leave the option out for the default)");
    if (value > (uint64_t(1) << (60 - shift))) throw Error(refuse + " (at most 2^60 bytes)");
    return value << shift;
}

} // namespace vdbdag
