// The tools a user would otherwise use, measured on the same grid for
// `vdbdag bench` (issue 7): OpenVDB files (no compression, zip, blosc, blosc
// with half floats), NanoVDB grids (float, Fp16, Fp8, Fp4, and FpN at the
// given absolute tolerances; float grids only) and ZFP's fixed-accuracy mode
// at the same tolerances (per 8^3 leaf, float and double grids). Each point
// gets its size, its max and RMS error over the active voxels (read back
// through the peer's own decoder or accessor), and its encode and decode
// times (median of up to `repeats`, within `budgetMs` per measurement).
#pragma once
#include <string>
#include <vector>

#include "src/bench/BenchPoint.h"

namespace vdbdag::bridge {

struct PeerOptions {
    std::vector<double> absTolerances;  // for NanoVDB FpN and ZFP
    int repeats = 3;
    double budgetMs = 1e300;            // bench::repeatAgain: no further repeat once a measurement took this long
    std::string scratchDirectory;       // for the .vdb files written (removed afterwards)
};

// Grid `gridIndex` of the .vdb file at `path`.
std::vector<bench::BenchPoint> measurePeers(const std::string& path, size_t gridIndex, const PeerOptions& options);

} // namespace vdbdag::bridge
