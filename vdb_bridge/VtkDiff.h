// Voxel-by-voxel comparison of two volumes (.vdb, .ssvdag or a dense scan each) for
// ParaView and scripts (`vdbdag diff A B [-o DIFF.vtu]`). Grids are paired
// as DiffPairing says (after --grid selection). For each pair, every voxel active
// in either grid gets a status: 0 same (bit-identical value), 1 value differs,
// 2 active only in A, 3 active only in B. Active tiles stay single cells when
// both grids hold the tile region uniformly, else they are walked voxel by
// voxel (the cell limit applies). The VTK cells carry a, b, abs_error
// (|a-b|, Euclidean for vectors), rel_error (abs_error / max(|a|,|b|), 0 when
// both are 0), status; a side that is inactive is NaN, and so are its errors.
// Statistics cover voxels active in both, tiles weighted by their voxels:
// max / mean / RMS / max relative error, and PSNR = 20 log10(peak / RMS)
// with peak = the value range (max - min; magnitudes for vectors) of A's
// active values.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "src/format/ReadLimits.h"

namespace vdbdag::bridge {

// How grids of A and B are paired (`--pair`): Auto pairs the two grids of
// two single-grid files whatever their names (a scan's grid is named after
// its file), else as Name; Name pairs grids of the same name, the k-th of a
// name in A with the k-th of that name in B; Order pairs them in file order.
enum class DiffPairing { Auto, Name, Order };

// Two transforms whose matrices differ by at most this fraction of A's
// smallest voxel size are reported equal (with a note), not as a difference.
inline constexpr double kTransformTolerance = 1e-6;

struct DiffOptions {
    std::vector<std::string> grids;  // empty: all
    DiffPairing pairing = DiffPairing::Auto;
    bool onlyDifferences = false;    // write only cells whose status is not 0
    uint64_t maxCells = 20'000'000;  // per written block
    std::string compressor = "zlib";
    // What each .ssvdag side may expand to (`--max-voxels`, `--max-memory`),
    // weighed before it is decoded.
    format::ReadLimits limits;
};

struct GridDiff {
    std::string name;
    size_t indexA = 0, indexB = 0;
    std::string valueType;
    std::array<uint64_t, 4> voxels{};  // per status, tiles counted as their voxels
    uint64_t cells = 0;                // cells written
    uint64_t nonFiniteErrors = 0;      // voxels active in both whose |a-b| is NaN or inf (not in the statistics)
    double maxAbsError = 0, meanAbsError = 0, rmsError = 0, maxRelError = 0;
    double peak = 0;                   // value range of A
    double psnr = 0;                   // dB; +inf when RMS is 0, NaN when the peak is 0
    // The same over every voxel active in A, with B's stored (inactive)
    // value where B has none: for a thresholded scan against its source,
    // encode's report (samples made inactive = voxels[2]).
    struct OverA {
        uint64_t voxels = 0;
        double maxAbsError = 0, meanAbsError = 0, rmsError = 0, psnr = 0;
    } ofA;
    bool differs() const { return voxels[1] + voxels[2] + voxels[3] > 0; }
};

struct DiffReport {
    std::vector<std::string> headerDifferences;  // grid count, transforms
    std::vector<std::string> notes;  // what is equal only within a tolerance, grids paired across names
    std::vector<GridDiff> grids;
    bool identical = true;
    uint64_t bytes = 0;  // written, when an output was given
};

// `output` empty: statistics only. Else .vtu (one grid pair) or .vtm.
DiffReport diffVolumes(const std::string& pathA, const std::string& pathB, const std::string& output, const DiffOptions& options);

} // namespace vdbdag::bridge
