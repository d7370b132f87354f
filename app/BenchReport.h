// Writes the results of `vdbdag bench`: report.json (every point),
// report.csv (one row per point), report.md (a table per grid, the matched
// comparisons against NanoVDB FpN and ZFP, the Pareto fronts) and the PNG
// plots of error against size and against decode time.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "src/bench/BenchPoint.h"

namespace vdbdag::app {

struct BenchRun {
    std::string input, sweep, machine;
    int repeats = 1, renderWidth = 0, renderHeight = 0;
    double budgetSeconds = 0;  // no repeat after a measurement took this long
    double seconds = 0;
    size_t gridCount = 0;  // grids measured
    std::vector<bench::BenchPoint> points;
};

nlohmann::json benchToJson(const BenchRun& run);
// Writes all files into `directory` (created if missing).
void writeBenchReport(const BenchRun& run, const std::string& directory);

} // namespace vdbdag::app
