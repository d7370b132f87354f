// A CLI11 transform for memory sizes ("512M", "4G", "1048576"), as
// src/util/ByteSize.h reads them. CLI11's AsSizeValue took "-1" (a huge
// size), 23-digit numbers and 0 (which the options then read as "the
// default"): each is refused with the option's own message.
#pragma once
#include <string>

#include <CLI/CLI.hpp>

#include "src/util/ByteSize.h"

namespace vdbdag::cli {

inline CLI::Validator byteSize() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            try {
                text = std::to_string(parseByteSize(text));
            } catch (const Error& e) {
                return e.what();
            }
            return std::string();
        },
        "SIZE");
}

} // namespace vdbdag::cli
