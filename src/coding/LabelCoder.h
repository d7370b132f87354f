// Lossless coding of categorical int32 entries (labels: atlases,
// segmentations), where a value's magnitude means nothing and a voxel
// mostly repeats one of its neighbours. Over a placed layout
// (PlacedWalk.h: each brick's voxels in spatial order, neighbours across
// bricks), each entry is coded as:
//   - "equals candidate i?" for the distinct values among its decoded
//     neighbours W, N, P, NE, NW, PN, PW, PNW (in that order, at most 4),
//     each bit under a context of the candidate's rank, how many of the 8
//     neighbours hold it, and how many distinct values they hold: a voxel
//     inside a region costs a small fraction of a bit, one on a boundary
//     picks the side it belongs to;
//   - else its rank in a move-to-front list of the 32 labels met most
//     recently (unary, a model per rank), or, when it is none of them, its
//     offset from minValue in as many bits as the range needs.
// An adaptive binary range coder (RangeCoder.h) codes every bit. The
// predicted window coding 7 (4 in the layout's brick order,
// attributes/PredictedWindows.h) when it is the smallest (docs/CODING.md).
//
// Generation 2 (window coding 17, what a writer writes since 2026-12-06;
// generation 1 above is codings 7 and 4, still read) codes the same
// decisions with more of the boundary's shape, bricks in raster order
// inside 32^3 blocks (BrickOrder::Raster, as the integers' models 2-4):
//   - "equals candidate i?" under the candidate's rank, WHICH of the ten
//     neighbours W, N, P, NE, NW, PN, PW, PNW, PE, PS hold it (a 10-bit
//     mask, not how many: a boundary's orientation says which side a voxel
//     falls on; the slice below ahead, PE and PS, says where the boundary
//     goes next) and how many distinct values the near eight hold; every
//     model learns its first bits fast (BitModel::warmUp: 12,288 models);
//   - else its rank in a move-to-front list of up to 1,024 labels met (an
//     atlas holds hundreds; generation 1's 32 sent most of them in plain
//     bits again), rank + 1 in Elias-gamma form with adaptive bits (its
//     bit length in unary, then the bits below the leading one per length
//     and position); rank = the list's length is a new label, in plain bits.
// On the shared atlases in raster order, 25-30 % smaller than generation 1
// (docs/CODING.md).
//
// Generation 3 (window coding 18, written since 2026-12-06 late; 17 still
// read) is generation 2 with tiles as neighbours (PlacedWalk.h's kTiles):
// a scan's solid 8^3 blocks are tiles (vdb_bridge/detail/SolidBlocks.h),
// coded first, each under the candidates of the tiles of its size W, N
// and P of it (their own models: which of the three hold a candidate);
// a voxel beside a tile sees the tile's label there. Without it a boundary
// brick beside a tile lost its neighbours on that side, and the atlases
// grew 3-11 % when their uniform blocks became tiles.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/coding/BrickValueCoder.h"

namespace vdbdag::coding {

// The newest label model generation, what a writer writes.
inline constexpr int kLatestLabelModel = 3;

// Every entry must lie in [minValue, maxValue] (throws vdbdag::Error).
// `generation`: 1, 2 or 3, as above.
std::vector<uint8_t> encodePlacedLabels(std::span<const int32_t> entries, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                                        BrickOrder order, int32_t minValue, int32_t maxValue, int generation = 1);

// Throws vdbdag::Error naming `what` on a corrupt stream (a label outside
// the range, too few or unused bytes); never reads outside `bytes`.
void decodePlacedLabels(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, std::span<const BrickPlace> places, BrickOrder order,
                        int32_t minValue, int32_t maxValue, std::span<int32_t> out, const std::string& what, int generation = 1);

} // namespace vdbdag::coding
