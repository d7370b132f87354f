// Lossy colours (Dado et al. §4.3, Table 2): the distinct colours of a vec3
// channel are clustered in CIELAB (D65) to at most 2^k representatives with
// Xiang's minimised maximum intercluster distance, i.e. Gonzalez's
// farthest-point clustering (a 2-approximation of the optimal max radius),
// followed by a few k-means passes that may move a centre to its cluster's
// mean only while no member gets farther than the clustering's maximum
// radius (so the maximum error keeps Xiang's bound and the mean drops).
// Every value is replaced by its cluster's representative, stored in the
// grid's own type (a vec3i stays an integer colour in 0..255), so the
// palette compressor then sees at most 2^k distinct values. The corners of
// the RGB cube (black, white, primaries, secondaries), when present, are
// centres that never move.
//
// Speed: the clustering runs on the distinct colours only and prunes with
// the triangle inequality (a point p of cluster a can move to a new centre c
// only if |a c| < 2 |a p|, so only clusters with |a c| < 2 radius(a) are
// scanned), which keeps it far below the O(n 2^k) worst case in practice.
//
// Accepted values: vec3s/vec3d components in [0, 1] (sRGB), vec3i in
// 0..255. NaN, Inf or out-of-range components are refused with an Error
// naming the grid: a colour grid with them is not an sRGB colour grid.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "src/volume/GridRecord.h"

namespace vdbdag::attributes {

// The error of a colour quantisation, measured on every entry (voxel or
// tile value) against its original: absolute error per R, G, B channel in
// 0..255 units and ΔE*94 (CieLab.h), like Dado et al.'s Table 2.
struct ColourReport {
    unsigned bits = 0;                 // k: at most 2^k colours
    uint64_t entries = 0;              // values quantised
    uint64_t distinctBefore = 0, distinctAfter = 0;
    uint64_t changed = 0;              // entries whose value changed
    std::array<double, 3> meanAbsError{}, maxAbsError{};  // per channel, 0..255 units
    double meanDeltaE94 = 0, maxDeltaE94 = 0;
};

// True for vec3 value types.
inline bool isVec3Type(ValueType type) { return type == ValueType::Vec3S || type == ValueType::Vec3D || type == ValueType::Vec3I; }

// Default colour-grid names (case-insensitive): Cd, color, colour,
// colorGrid, colourGrid, rgb.
bool hasColourGridName(const std::string& name);

// Quantises `values` (raw bytes of `type`, one entry per valueSize(type)
// bytes) in place to at most 2^bits colours, bits in 1..16. Deterministic
// (whatever the thread count). `refinePasses` k-means passes follow the
// farthest-point clustering; they lower the mean error and never raise the
// maximum CIELAB distance (ΔE*76) above the clustering's. Throws
// Error("<what>: ...") for NaN/Inf/out-of-range components.
inline constexpr unsigned kColourRefinePasses = 3;
ColourReport quantiseColours(std::vector<uint8_t>& values, ValueType type, unsigned bits, const std::string& what,
                             unsigned refinePasses = kColourRefinePasses);

// sRGB components of one raw value in [0, 1] (vec3i divided by 255).
std::array<double, 3> colourOf(const uint8_t* value, ValueType type);

} // namespace vdbdag::attributes
