// The tool's version, and what every report of ours carries (the CLI's
// --json output, the bench report): the keys that say which tool and which
// .ssvdag format version wrote it.
#pragma once
#include <nlohmann/json.hpp>

#include "src/format/SsvdagContainer.h"

namespace vdbdag::app {

inline constexpr const char* kToolVersion = "0.1.0";

inline void addVersions(nlohmann::json& report) {
    report["tool"] = "vdbdag";
    report["tool_version"] = kToolVersion;
    if (!report.contains("format_version")) report["format_version"] = format::kFormatVersion;  // an .ssvdag's report has its own (InputReport.cpp)
}

} // namespace vdbdag::app
