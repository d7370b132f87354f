// The tool's version, and what every command's JSON report carries: the
// keys that say which tool and which .ssvdag format version wrote it.
#pragma once
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "src/format/SsvdagContainer.h"

namespace vdbdag::cli {

inline constexpr const char* kToolVersion = "0.1.0";

inline void addVersions(nlohmann::json& report) {
    report["tool"] = "vdbdag";
    report["tool_version"] = kToolVersion;
    report["format_version"] = format::kFormatVersion;
}

// `report` with the versions, on stdout (text that is not UTF-8, such as a
// Latin-1 DICOM description, is replaced, never thrown on).
inline void printJson(nlohmann::json report) {
    if (report.is_object()) addVersions(report);
    fmt::print("{}\n", report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace));
}

} // namespace vdbdag::cli
