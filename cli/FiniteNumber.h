// A CLI11 check that an option's value is a finite number: CLI11's Range
// and PositiveNumber let NaN through (every comparison with NaN is false),
// and "inf" parses as a double.
#pragma once
#include <cmath>
#include <string>

#include <CLI/CLI.hpp>

namespace vdbdag::cli {

inline CLI::Validator finiteNumber() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            double value = 0;
            if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value)) return "'" + text + "' is not a finite number";
            return std::string();
        },
        "FINITE");
}

} // namespace vdbdag::cli
