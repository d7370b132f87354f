// Float32 entries on a rescale lattice (GridRecord::rescale), coded as
// their integers: a rescaled scan (a PET's Bq/ml = sample x 2.0222414) holds
// float values that are each float(k x slope + intercept) for the integer
// sample k, and the integer coder (ContextChannel.h, coding 3) codes the k
// far better than any coding of the float bits. What a predicted window of
// a float grid stores as coding 5 (PredictedWindows.h).
//
// The lattice value of k is defined exactly (rescaledFloat, below): the
// product k x slope rounded to double on its own, the intercept added and
// rounded to double, then rounded to float (round to nearest even each
// time). No fused multiply-add on any machine, so a file decodes to the
// same bits everywhere. The encoder checks every entry against it; those
// off the lattice (NaN, a value edited after import) are exceptions kept
// with their bits, and a window with many of them is not coded this way.
//
// Payload: f64 slope, f64 intercept (finite, slope != 0), u32 exception
// count X, X x (u32 entry index within the window, strictly increasing;
// u32 the entry's float bits), then a ContextChannel payload (as coding 6:
// neighbours across bricks, bricks in spatial order) of the window's
// integers, where an exception stands in as the integer of the entry
// before it (0 for the first).
#pragma once
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "src/coding/BrickValueCoder.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::attributes {

// The lattice's value of `k` (see above). The volatile store keeps the
// product a double of its own, which no compiler may fuse with the sum.
inline float rescaledFloat(int64_t k, const ValueRescale& r) {
    volatile double product = double(k) * r.slope;
    return float(product + r.intercept);
}

// Entries (little-endian float32) over `layout`/`places` as coding 5, or
// nothing when more than a sixteenth of them lie off the lattice or the
// integers leave int32.
// `model`: the integers' model generation, 4 (coding 16), 3 (coding 14), 2 (coding 11) or 1 (coding 5);
// `tileNeighbours` (coding 20): generation 4's walk with tiles as neighbours (ContextChannel.h).
// `codeAside`: coding/IntVolumeCoder.h's IntCoderOptions::codeAside (speed only).
std::optional<std::vector<uint8_t>> encodeRescaledFloats(std::span<const uint8_t> values, std::span<const uint64_t> layout,
                                                         std::span<const coding::BrickPlace> places, const ValueRescale& rescale,
                                                         int model = coding::kLatestIntModel, bool tileNeighbours = false, bool codeAside = false,
                                                         std::span<const uint8_t> reference = {});

// Inverse; validates the payload against `layout` and `entries` (throws
// vdbdag::Error starting with `what`).
std::vector<uint8_t> decodeRescaledFloats(std::span<const uint8_t> payload, std::span<const uint64_t> layout, uint64_t entries, const std::string& what,
                                          std::span<const coding::BrickPlace> places, int model, bool tileNeighbours = false,
                                          std::span<const uint8_t> reference = {});

// `reference` (coding 22): a series' previous volume, float32 entries in
// the same order as the window's, whose integers on this window's lattice
// (referenceIntegers) are the coder's reference (ContextChannel.h).
// The integer of a reference entry: (v - intercept) / slope rounded to the
// nearest (ties to even) and kept inside int32 less one at each end; 0 for
// NaN. IEEE doubles, a subtraction then a division: the same bits on every
// machine.
std::vector<int32_t> referenceIntegers(std::span<const uint8_t> reference, const ValueRescale& rescale);

} // namespace vdbdag::attributes
