// Lossless coding of float32 entries over a placed layout (BrickValueCoder.h:
// brick instances with their corners and mirrors), bit for bit: the window
// coding 8 of a float grid's predicted windows (attributes/PredictedWindows.h,
// docs/CODING.md "Floats").
//
// The walk is PlacedWalk.h's in spatial order (tiles first, then bricks by
// the Morton order of their corners, each brick's voxels in raster order),
// with the causal neighbours W, N, NW, P, PW, PN, PNW and WW, NN, PP two
// voxels back, wherever they were coded before in the same call. Eight
// predictions are made in double precision from the neighbours present:
//   0 Lorenzo       W + N + P - NW - PW - PN + PNW   (exact on trilinear)
//   1-3 planar      W + N - NW, W + P - PW, N + P - PN
//   4-6 linear      2W - WW, 2N - NN, 2P - PP        (distance fields: a
//                   signed distance is linear along its gradient)
//   7 mean          of W, N, P (0 with none)
// and the one whose errors at W, N, P and NW sum least is used (choosing
// beat blending on every level set and fog tried: the bunny level set
// 6.42 MB chosen, 7.42 MB blended by inverse squared error).
//
// Values are compared as integers: ordered(bits) maps float bits to uint32
// monotonically (-NaN < -inf < ... < -0 < +0 < ... < +inf < +NaN), shifted
// right by the window's common count of zero low mantissa bits (13 for a
// file stored as half floats). The residual ordered(value) - ordered(
// prediction), shifted, is coded as its bit length (a 6-level binary tree)
// under one of 64 contexts, its sign, the two bits below its leading one
// (modelled per context and length) and the remaining bits as they are.
// The context is the bit length, in the same units, of the step from the
// prediction to the prediction plus the chosen predictor's mean local error
// (in half-length steps): how far off the neighbours' predictions were, in
// the units of this value's magnitude.
//
// Bit exactness on every machine: neighbours that are NaN or infinite are
// not used; subnormal ones count as 0, and every double-to-float rounding
// goes through one function that returns 0 below FLT_MIN, so flush-to-zero
// and denormals-are-zero modes change nothing; the arithmetic is compiled
// without contraction (no fused multiply-add). Round-to-nearest is assumed.
//
// Payload: u8 model generation (0), u8 shift (0..31), the range-coded stream.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/coding/BrickValueCoder.h"

namespace vdbdag::coding {

// `bits`: the float32 entries' bit patterns, as many as `layout` implies.
// Throws vdbdag::Error when the layout, its places and the entries disagree.
std::vector<uint8_t> encodePlacedFloats(std::span<const uint32_t> bits, std::span<const uint64_t> layout, std::span<const BrickPlace> places);

// Inverse: fills `out` (as many entries as `layout` implies). Throws
// vdbdag::Error naming `what` on a corrupt or truncated payload; never reads
// outside it; its time is bounded by the entry count.
void decodePlacedFloats(std::span<const uint8_t> payload, std::span<const uint64_t> layout, std::span<const BrickPlace> places, std::span<uint32_t> out,
                        const std::string& what);

// vec3s entries (window coding 9): `bits` holds each entry's x, y and z
// bits in turn. Each component is predicted from the same component of the
// neighbours, as above; component c > 0 is coded under contexts of its own,
// split by how component c - 1's residual at the same voxel compared with
// its context's expectation (shorter, about the same, longer): turbulence
// shows in every component at once. Payload: u8 generation (0), 3 x u8
// shift (one per component), the range-coded stream.
std::vector<uint8_t> encodePlacedFloatVectors(std::span<const uint32_t> bits, std::span<const uint64_t> layout, std::span<const BrickPlace> places);
void decodePlacedFloatVectors(std::span<const uint8_t> payload, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                              std::span<uint32_t> out, const std::string& what);

} // namespace vdbdag::coding
