// The benchmark harness behind `vdbdag bench`: every lossy setting of
// vdbdag against the lossless encoding and against the tools a user would
// otherwise pick (OpenVDB, NanoVDB, ZFP), measured in one run on the same
// grid: size, value error, render error (PSNR, SSIM), and encode, decode and
// trace times (median of repeats with the spread). BenchReport.h writes
// what it measures (report.md/.csv/.json and PNG plots).
#pragma once
#include <string>
#include <vector>

#include "app/BenchReport.h"

namespace vdbdag::app {

struct BenchRequest {
    std::string input;               // a .vdb file
    std::string sweep = "default";  // quick, default or full: which settings, and the default repeats
    std::vector<std::string> grids;  // only these grids (all when empty)
    int width = 480, height = 360;   // the render that times tracing and measures image error
    int repeats = 0;                 // timed runs per measurement (0: the sweep's)
    double budgetSeconds = 3;        // no further repeat once a measurement took this long (at least one run)
};

// Measures every grid `request` names, with progress on a terminal (quiet
// when piped, or after setQuiet). Throws vdbdag::Error when the input cannot
// be read or no grid matches.
BenchRun runBenchmark(const BenchRequest& request);

} // namespace vdbdag::app
