// Octahedral normal vectors (ONV; Cigolle et al. 2014, used by Dado et al.
// §4.3): a unit vector folded onto the octahedron and unfolded to the unit
// square, each of the two coordinates stored as a k/2-bit signed normalised
// integer. Encoding picks the best of the 4 neighbouring lattice points
// ("precise" variant), so the angular error stays below the bound the
// tests check. Robust to +-0 components and zero-length input (which encodes
// +z and is reported).
#pragma once
#include <array>
#include <cstdint>

namespace vdbdag::attributes {

struct OctahedralCode {
    uint32_t bits;  // the two k/2-bit fields, x in the low half
};

// k in [4, 32], even. Returns the code; `zeroLength` is set when the input
// had no direction (encoded as +z).
OctahedralCode encodeOctahedral(const std::array<float, 3>& n, unsigned k, bool* zeroLength = nullptr);
std::array<float, 3> decodeOctahedral(OctahedralCode code, unsigned k);

// Angle in degrees between two (not necessarily unit) vectors; 0 for zero vectors.
double angleDegrees(const std::array<float, 3>& a, const std::array<float, 3>& b);

} // namespace vdbdag::attributes
