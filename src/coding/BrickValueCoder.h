// Lossless (and near-lossless) coding of int32 entries in a DAG's attribute
// order: the brick instances of a layout (attributes/PredictedChannel.h: per
// instance its stored mask, 0 for a tile) in order, each brick's entries in
// its stored raster order (bit i: x = i & 3, y = (i >> 2) & 3, z = i >> 4).
// Each entry is predicted, context-modelled and range coded by the model of
// SamplePredictor.h from its causal neighbours inside the same brick (W, N,
// NW, NE in its slice; P, PW, PN, PNW in the slice below; a missing one is
// replaced as IntVolumeCoder replaces a neighbour beyond the volume's face,
// and an entry with none at all is predicted by the previous entry in
// attribute order, whose record then stands in for W's). A tile is one
// entry without neighbours.
//
// It is the coding of a predicted window that beats brick MED + zstd byte
// planes (PredictedChannel.h) by modelling the residuals instead of
// compressing them as bytes; neighbours across brick boundaries are the
// next step (docs/CODING.md).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/coding/IntVolumeCoder.h"

namespace vdbdag::coding {

// Codes `entries` (as many as `layout` implies). Throws vdbdag::Error when
// an entry lies outside [minValue, maxValue] or the layout and the entries
// disagree. With near > 0, `reconstructed` (if given) receives what the
// decoder will produce.
std::vector<uint8_t> encodeBrickValues(std::span<const int32_t> entries, std::span<const uint64_t> layout, const IntCoderOptions& options,
                                       std::vector<int32_t>* reconstructed = nullptr);

// Decodes into `out` (as many entries as `layout` implies). Throws
// vdbdag::Error naming `what` on a corrupt or truncated stream; never reads
// outside `bytes`; its time is bounded by the entry count.
void decodeBrickValues(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, const IntCoderOptions& options, std::span<int32_t> out,
                       const std::string& what);

// The entries `layout` implies (a tile counts one).
uint64_t layoutEntryCount(std::span<const uint64_t> layout);

// Where a brick instance of a layout lies: its minimum corner in index space
// (multiples of 4) and the reflection accumulated on the way down to it
// (bit 0: x, 1: y, 2: z; DESIGN.md invariant 2). A tile's place: tilePlace.
struct BrickPlace {
    int32_t x = 0, y = 0, z = 0;
    uint32_t mirror = 0;
};
// A tile's place: its corner, the log2 of its size in `mirror` (PlacedWalk.h).
inline BrickPlace tilePlace(int64_t x, int64_t y, int64_t z, unsigned log2Size) { return {int32_t(x), int32_t(y), int32_t(z), log2Size}; }

// The order a placed walk visits a layout's instances in. Attribute: the
// layout's own (window codings 3 and 4). Spatial: its tiles, then its
// bricks in the Morton order of their corners (codings 5-9), where every causal
// neighbour's brick comes before the brick, whatever the mirrors on the
// DAG's paths (under a mirror a symmetric DAG visits its children from the
// far side, so in attribute order a PET's bricks lose a fifth of their
// neighbours and the window costs 24 % more).
// Raster (codings 10, 11): 32^3-voxel blocks in Morton order, the bricks of
// a block in (z, y, x) order of their corners, so that inside a block the
// slice of bricks below is wholly coded before a brick (Morton order leaves
// some of it for later): the far neighbours of generation 2
// (LeastSquaresPredictor.h) are there more often (PlacedWalk.h).
enum class BrickOrder : uint8_t { Attribute, Spatial, Raster };

// The order the spatially ordered codings of a model generation walk in
// (IntCoderOptions::model): Raster for generation 2, Spatial before.
inline BrickOrder spatialOrderOf(int model) { return model >= 2 ? BrickOrder::Raster : BrickOrder::Spatial; }

// The same coding with neighbours across brick boundaries: with `places`
// (one per layout entry), each brick's voxels are visited in spatial raster
// order (x fastest; the entry of spatial voxel p is the rank of its stored
// bit, dag_access.h dagStoredBit) and predicted from the spatial neighbours
// already coded, in this brick or in any brick before it in the same call.
// A dense region in attribute (Morton) order then has the whole causal
// neighbourhood of IntVolumeCoder almost everywhere.
std::vector<uint8_t> encodePlacedBrickValues(std::span<const int32_t> entries, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                                             BrickOrder order, const IntCoderOptions& options, std::vector<int32_t>* reconstructed = nullptr);
void decodePlacedBrickValues(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, std::span<const BrickPlace> places, BrickOrder order,
                             const IntCoderOptions& options, std::span<int32_t> out, const std::string& what);

} // namespace vdbdag::coding
