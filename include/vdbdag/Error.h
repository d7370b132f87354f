// Part of the public reader API (<vdbdag/vdbdag.h>).
// The one exception type vdbdag throws for bad input or impossible requests.
// Its message is a single line meant for the user ("FILE: what is wrong");
// the CLI prints it and exits non-zero. Control characters in the message
// (from a header's text, a file name) are escaped as \xNN when the Error is
// made, so no message can move the terminal's cursor, change its colours,
// break the line or be cut short by a NUL.
#pragma once
#include <stdexcept>
#include <string>

// Symbols of the public API, exported from libvdbdag (built with hidden
// visibility: nothing else of it is seen from outside).
#ifndef VDBDAG_API
#define VDBDAG_API __attribute__((visibility("default")))
#endif

namespace vdbdag {

inline std::string escapeControlCharacters(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        const auto u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u != 0x7f) {
            out += c;
            continue;
        }
        static const char* kHex = "0123456789abcdef";
        out += "\\x";
        out += kHex[u >> 4];
        out += kHex[u & 15];
    }
    return out;
}

struct VDBDAG_API Error : std::runtime_error {
    explicit Error(const std::string& message) : std::runtime_error(escapeControlCharacters(message)) {}
    explicit Error(const char* message) : Error(std::string(message)) {}
};

} // namespace vdbdag
