// What every command's JSON report carries (app/ReportVersions.h), printed.
#pragma once
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "app/ReportVersions.h"

namespace vdbdag::cli {

using app::addVersions;
using app::kToolVersion;

// `report` with the versions, on stdout (text that is not UTF-8, such as a
// Latin-1 DICOM description, is replaced, never thrown on).
inline void printJson(nlohmann::json report) {
    if (report.is_object()) addVersions(report);
    fmt::print("{}\n", report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace));
}

} // namespace vdbdag::cli
