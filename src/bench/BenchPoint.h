// One measured point of `vdbdag bench`: a tool (vdbdag or a peer: OpenVDB,
// NanoVDB, ZFP) at one setting, with its size, its error and its times, as
// Benthin et al. ask: error next to memory and run time, never alone.
#pragma once
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace vdbdag::bench {

// Repeated timings: median with the spread.
struct Timing {
    double medianMs = std::numeric_limits<double>::quiet_NaN();
    double minMs = std::numeric_limits<double>::quiet_NaN();
    double maxMs = std::numeric_limits<double>::quiet_NaN();
    int runs = 0;
    bool measured() const { return runs > 0; }
};
Timing summarise(std::vector<double> samplesMs);

inline double totalMs(const std::vector<double>& samplesMs) {
    double sum = 0;
    for (double ms : samplesMs) sum += ms;
    return sum;
}
// Whether to time run number `done` (0-based) of a measurement: at most
// `repeats` runs, and after the first only while the runs so far took less
// than `budgetMs` in all (a 20M-voxel grid's encode then runs once; small
// grids get every repeat). Timing::runs reports what was done.
inline bool repeatAgain(int done, int repeats, double spentMs, double budgetMs) {
    return done < repeats && (done == 0 || spentMs < budgetMs);
}

inline const std::string kValueError = "value";
inline const std::string kColourError = "colour dE94";
inline const std::string kNormalError = "normal angle deg";

struct BenchPoint {
    std::string grid;       // grid name
    std::string tool;       // "vdbdag", "OpenVDB", "NanoVDB", "ZFP"
    std::string setting;    // e.g. "lossless", "abs 1e-3", "Fp8", "blosc"
    std::string family;     // points of one family form a curve in the plots (e.g. "vdbdag abs")
    uint64_t bytes = 0;     // stored size (file, or the peer's compressed stream)
    uint64_t traceableBytes = 0;  // in-memory traceable size (vdbdag, NanoVDB); 0 if not applicable
    uint64_t activeVoxels = 0;
    uint64_t rawBytes = 0;  // active values as a plain array (the rate's denominator)
    // What maxError/rmsError/meanError measure: kValueError (the grid's
    // values, absolute, in the grid's units), kColourError (CIELAB ΔE94 of
    // the colour grid's quantised colours, Dado et al. §4) or kNormalError
    // (angle in degrees between the stored ONV normal and the exact one).
    // Points are only compared (fronts, plots) within one metric.
    std::string metric = kValueError;
    double maxError = 0, rmsError = 0;   // errors against the input (0 = exact)
    double meanError = std::numeric_limits<double>::quiet_NaN();  // mean of the metric, where it is reported
    bool exact = true;                   // bit-exact in the metric's channel
    double psnr = std::numeric_limits<double>::quiet_NaN();  // render vs the lossless render (dB)
    double ssim = std::numeric_limits<double>::quiet_NaN();
    Timing encode, decode, trace;
    double raysPerSecond = std::numeric_limits<double>::quiet_NaN();
    std::string note;

    double bitsPerVoxel() const { return activeVoxels ? 8.0 * double(bytes) / double(activeVoxels) : 0; }
    double rate() const { return rawBytes ? double(bytes) / double(rawBytes) : 0; }
};

// Indices of the points on the Pareto front of (x, y), both minimised:
// no other point is at least as good on both and better on one.
std::vector<size_t> paretoFront(const std::vector<double>& x, const std::vector<double>& y);

} // namespace vdbdag::bench
