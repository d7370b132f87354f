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
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/coding/BrickValueCoder.h"

namespace vdbdag::coding {

// Every entry must lie in [minValue, maxValue] (throws vdbdag::Error).
std::vector<uint8_t> encodePlacedLabels(std::span<const int32_t> entries, std::span<const uint64_t> layout, std::span<const BrickPlace> places,
                                        BrickOrder order, int32_t minValue, int32_t maxValue);

// Throws vdbdag::Error naming `what` on a corrupt stream (a label outside
// the range, too few or unused bytes); never reads outside `bytes`.
void decodePlacedLabels(std::span<const uint8_t> bytes, std::span<const uint64_t> layout, std::span<const BrickPlace> places, BrickOrder order,
                        int32_t minValue, int32_t maxValue, std::span<int32_t> out, const std::string& what);

} // namespace vdbdag::coding
