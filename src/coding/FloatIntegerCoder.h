// Lossless coding of float32 entries as the integers of their order,
// through the integer coder (window coding 12 of a float grid's predicted
// windows, attributes/PredictedWindows.h; docs/CODING.md "Floats").
//
// Why: floats stored at reduced precision (half floats, as smoke caches
// are saved: 13 zero low mantissa bits) are integers of at most 19
// significant bits once those bits are dropped, and on those the integer
// coder's least-squares fit of 19 neighbours (LeastSquaresPredictor.h)
// predicts better than the float coder's choice among eight fixed
// predictors: smoke1's density codes 2.4 % smaller. On full-precision
// floats it loses (1.3 to 8 times larger on the shared level sets and
// fogs), so the writer tries it only on reduced-precision windows and keeps
// it where a sample says it wins (PredictedWindowWriter.cpp).
//
// The integers: with s the entries' common count of zero low bits (sign bit
// aside) and M = (bits & 0x7FFFFFFF) >> s, a positive float (sign 0) is M
// and a negative one is -1 - M: monotonic in the floats' order (-0 < +0,
// NaNs at the ends) and one-to-one, so every bit pattern comes back. They
// are coded by encodePlacedBrickValues in raster brick order under model
// generation 4 (the header's generation 2; generations 0 and 1, still read:
// model generations 2 and 3), within [min, max] of the window's integers.
//
// Payload: u8 generation (2; 0 and 1 still read), u8 s (0..31), i32 min, i32 max
// (little-endian), the integer coder's stream.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/coding/BrickValueCoder.h"

namespace vdbdag::coding {

// The common count of zero low bits of `bits` (sign bit aside; 31 when
// every entry is +-0).
unsigned floatZeroLowBits(std::span<const uint32_t> bits);

// `bits`: the float32 entries' bit patterns, as many as `layout` implies.
// Throws vdbdag::Error when the layout, its places and the entries disagree.
// `codeAside`: IntCoderOptions::codeAside (speed only).
std::vector<uint8_t> encodePlacedFloatIntegers(std::span<const uint32_t> bits, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                                               bool codeAside = false);

// Inverse: fills `out` (as many entries as `layout` implies). Throws
// vdbdag::Error naming `what` on a corrupt or truncated payload; never reads
// outside it; its time is bounded by the entry count.
void decodePlacedFloatIntegers(std::span<const uint8_t> payload, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                               std::span<uint32_t> out, const std::string& what);

} // namespace vdbdag::coding
