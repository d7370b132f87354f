// The timing helpers of the peer benchmarks (int_coder_bench, float_peers_bench):
// seconds between two clock readings, and the median of repeated runs.
#pragma once
#include <algorithm>
#include <chrono>
#include <vector>

namespace vdbdag::benchtools {

using Clock = std::chrono::steady_clock;
inline double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }
inline double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

} // namespace vdbdag::benchtools
