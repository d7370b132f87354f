// How a dense scan's samples become 4^3 bricks, shared by the in-memory
// import (DenseImport.cpp) and the cube-by-cube source (DenseCubes.cpp), so
// both give the same bricks, values and threshold statistics bit for bit.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <bit>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

#include "src/attributes/RescaledFloats.h"
#include "src/util/ScratchFile.h"
#include "src/volume/CubeSource.h"
#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/detail/SolidBlocks.h"

namespace vdbdag::bridge::detail {

struct Thresholds {
    bool below = false, above = false;
    double belowValue = 0, aboveValue = 0;
    std::optional<double> background;  // --background-value; else the removed samples' mean
    // Solid 8^3 blocks become tiles (SolidBlocks.h; `--no-tiles` keeps
    // every voxel in its brick). Not a threshold, but part of the same rule
    // from samples to the grid.
    bool solidBlocks = true;
    bool any() const { return below || above; }
    bool removes(double x) const { return (below && x < belowValue) || (above && x > aboveValue); }
};

// What one pass accumulates (per brick row, then reduced in row order).
struct PassStats {
    uint64_t removed = 0, changed = 0;
    double removedSum = 0;
    double min = std::numeric_limits<double>::infinity(), max = -std::numeric_limits<double>::infinity();
    double maxAbs = 0, sumAbs = 0, sumSq = 0;
    void add(const PassStats& o) {
        removed += o.removed;
        changed += o.changed;
        removedSum += o.removedSum;
        min = std::min(min, o.min);
        max = std::max(max, o.max);
        maxAbs = std::max(maxAbs, o.maxAbs);
        sumAbs += o.sumAbs;
        sumSq += o.sumSq;
    }
};

// Whether every value is an integer of int32's range that float(k) gives
// back bit for bit (-0.0 and NaN are not): a float32 scan saved from
// integer samples (a label map, a series converted to float). Such a grid's
// rescale hint (GridRecord::rescale) is the lattice of slope 1, so that the
// value coder codes the integers (attributes/RescaledFloats.h) and not the
// floats' bits: mpld_asl.nii.gz, float32 of integers, 1,201,829 bytes coded
// as floats. Only a hint: the coder checks every value, and no metadata
// says it.
inline bool onIntegerLattice(float f) { return std::fabs(f) < 0x1p31f && f == std::trunc(f) && !(f == 0 && std::signbit(f)); }
inline bool integerLattice(std::span<const float> values) {
    bool all = true;
    for (const float f : values) all &= onIntegerLattice(f);
    return all;
}

// Stored sample S -> grid value V: the header's rescale (exact in integers
// when both slope and intercept are integral; importDense chose V so the
// range fits), the thresholds and the slices without data.
template <typename S, typename V>
struct SampleRule {
    SampleRule(const DenseVolume& v, const Thresholds& thresholds, V backgroundValue)
        : th(thresholds), background(backgroundValue), missingSlices(v.missingSlices), slope(v.rescaleSlope), intercept(v.rescaleIntercept),
          rescaled(v.rescaleSlope != 1 || v.rescaleIntercept != 0) {}
    V convert(S s) const {
        if (!rescaled) return V(s);
        if constexpr (std::is_integral_v<V>) return V(int64_t(s) * int64_t(slope) + int64_t(intercept));
        else if constexpr (std::is_same_v<V, float> && std::is_integral_v<S>) return attributes::rescaledFloat(int64_t(s), {slope, intercept});  // the lattice the value coder checks
        else return V(double(s) * slope + intercept);
    }
    bool missing(int64_t z) const { return !missingSlices.empty() && std::binary_search(missingSlices.begin(), missingSlices.end(), z); }

    Thresholds th;
    V background;
    std::vector<int64_t> missingSlices;
    double slope, intercept;
    bool rescaled;
};

// One brick: the samples at s[z * strideZ + y * strideY + x] for x < lx,
// y < ly, z < lz (the brick's part inside the volume), whose first slice is
// slice z0 of the scan. Appends the kept values in bit order (x + 4y + 16z)
// and returns the mask; removed samples add to `stats`.
template <typename S, typename V>
uint64_t cutBrick(const SampleRule<S, V>& rule, const S* s, size_t strideY, size_t strideZ, int64_t lx, int64_t ly, int64_t lz, int64_t z0,
                  PassStats& stats, std::vector<V>& values) {
    uint64_t mask = 0;
    for (int bit = 0; bit < 64; ++bit) {
        const int64_t x = bit & 3, y = (bit >> 2) & 3, z = bit >> 4;
        if (x >= lx || y >= ly || z >= lz || rule.missing(z0 + z)) continue;
        const V sample = rule.convert(s[size_t(z) * strideZ + size_t(y) * strideY + size_t(x)]);
        const double d = double(sample);
        if (rule.th.any() && rule.th.removes(d)) {
            const double change = std::abs(d - double(rule.background));
            if (change != 0) ++stats.changed;
            stats.maxAbs = std::max(stats.maxAbs, change);
            stats.sumAbs += change;
            stats.sumSq += change * change;
            continue;
        }
        mask |= uint64_t(1) << bit;
        values.push_back(sample);
    }
    return mask;
}

// A scan's stored samples in a scratch file (slice after slice, as read,
// host byte order) and which bricks hold kept samples: what the cube
// source reads back.
struct DenseCubeScratch {
    std::shared_ptr<ScratchFile> file;
    int64_t cols = 0, rows = 0, slabs = 0;  // bricks along x, y, z
    std::vector<uint64_t> nonEmpty;         // bit (slab * rows + row) * cols + col
    LayerSummary summary;
    SolidBlocks blocks;  // read back as tiles (none: every brick is read)
    void add(const Brick& b) {
        const uint64_t i = (uint64_t(b.z / 4) * uint64_t(rows) + uint64_t(b.y / 4)) * uint64_t(cols) + uint64_t(b.x / 4);
        nonEmpty[i / 64] |= uint64_t(1) << (i % 64);
        ++summary.bricks;
        summary.voxels += uint64_t(std::popcount(b.mask));
        summary.extend(b.x, b.y, b.z, 4);
    }
    bool has(int64_t col, int64_t row, int64_t slab) const {
        const uint64_t i = (uint64_t(slab) * uint64_t(rows) + uint64_t(row)) * uint64_t(cols) + uint64_t(col);
        return (nonEmpty[i / 64] >> (i % 64)) & 1u;
    }
};

// The cube source over `scratch` (DenseCubes.cpp); `header` is the grid's
// record without voxels.
template <typename S, typename V>
std::unique_ptr<CubeSource> makeDenseCubes(const DenseVolume& v, const SampleRule<S, V>& rule, DenseCubeScratch scratch, const GridRecord& header);

} // namespace vdbdag::bridge::detail
