// The smallest and largest of a channel's values, as `info` prints them and
// an .ssvdag file's Summary section stores them (docs/FORMAT.md 10.1).
//
// The order is the value type's `<` (OpenVDB's: scalars as themselves,
// vectors lexicographically, as math::Tuple), made total so that the range
// is a function of the set of values and not of their order: any encoder
// path (in memory, cube by cube, in windows on several threads or several
// processes, each share's range merged) finds the same bits.
//  - A value with a NaN (a component of a vector) takes no part: NaN is
//    unordered, and where it fell first a sequential `<` would keep it.
//  - -0.0 and +0.0 compare equal under `<`; the range keeps -0.0 as the
//    smaller (IEEE 754 totalOrder), so both orders give the same bits.
// No values, or only NaNs: an empty range.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "src/volume/GridRecord.h"

namespace vdbdag::attributes {

struct ValueRange {
    std::vector<uint8_t> min, max;  // valueSize bytes each; both empty when no value took part
    bool empty() const { return min.empty(); }
    // Values back to back (valueSize(type) bytes each).
    void add(ValueType type, std::span<const uint8_t> values);
    // Another part of the same channel's range.
    void merge(ValueType type, const ValueRange& other);
};

} // namespace vdbdag::attributes
