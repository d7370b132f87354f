// Timing summaries and the Pareto front; see BenchPoint.h.
#include "src/bench/BenchPoint.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace vdbdag::bench {

Timing summarise(std::vector<double> samples) {
    Timing t;
    samples.erase(std::remove_if(samples.begin(), samples.end(), [](double v) { return !std::isfinite(v); }), samples.end());
    if (samples.empty()) return t;
    std::sort(samples.begin(), samples.end());
    t.runs = int(samples.size());
    t.minMs = samples.front();
    t.maxMs = samples.back();
    const size_t n = samples.size();
    t.medianMs = n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
    return t;
}

std::vector<size_t> paretoFront(const std::vector<double>& x, const std::vector<double>& y) {
    std::vector<size_t> order(x.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return x[a] != x[b] ? x[a] < x[b] : y[a] < y[b]; });
    std::vector<size_t> front;
    double best = std::numeric_limits<double>::infinity();
    for (size_t i : order) {
        if (!std::isfinite(x[i]) || std::isnan(y[i])) continue;
        if (y[i] < best) {
            front.push_back(i);
            best = y[i];
        }
    }
    std::sort(front.begin(), front.end());
    return front;
}

} // namespace vdbdag::bench
