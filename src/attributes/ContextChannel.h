// An int32 attribute channel (or a predicted window of one) coded by the
// context-modelled brick coder (coding/BrickValueCoder.h): each entry
// predicted from its neighbours in its 4^3 brick by six blended predictors,
// its residual range coded under an activity context. What a predicted
// window stores as coding 2, or with neighbours across bricks as coding 3,
// or as labels (coding/LabelCoder.h) as coding 4 (PredictedWindows.h), when
// it is smaller than the window's palettes.
//
// Payload: u8 value size (4), u32 near (0: lossless; n: every entry within
// n of what was coded, JPEG-LS NEAR; today's writer writes 0), u32 step
// (>= 1: every entry is minValue + step k, and the coder codes k; the
// greatest common divisor of the entries above their minimum, > 1 for
// values quantised by --abs-error), i32 minValue, i32 maxValue (the
// entries' range, which bounds every prediction and the residuals' modulo;
// step divides maxValue - minValue), u64 n (entries), then the coder's
// stream to the end. The stream's model generation (coding/SamplePredictor.h)
// is 0 without places or in attribute order (codings 2, 3); in spatial order
// the window's coding says it: 1 (codings 5, 6) or 2 (codings 10, 11).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/coding/BrickValueCoder.h"

namespace vdbdag::attributes {

// `values`: n little-endian int32 entries; `layout` as encodePredicted's.
// With `places` (one per layout entry), neighbours come from the bricks
// around too (codings 6 and 3, encodePlacedBrickValues, its bricks visited
// in `order`); without, from each brick alone (coding 2).
// With `labels` (and places), the entries are coded as categories by
// coding/LabelCoder.h, its model generation `labelModel` (1: codings 7 and
// 4; 2: coding 17; 3: coding 18). `tileNeighbours` (coding 19): the
// integers' placed walk of generation 4 with tiles as neighbours.
// `model`: the generation in spatial order (ignored otherwise).
// `codeAside`: IntCoderOptions::codeAside (speed only).
// `reference` (codings 21 and 22: a placed walk of generation 3 or 4, not
// labels): a series' previous volume, one entry per entry of `values` in
// the same order, as IntCoderOptions::reference; the coder sees each as
// the entries are seen: t where the step is 1, else (t - minimum) / step
// rounded down.
std::vector<uint8_t> encodeContextChannel(std::span<const uint8_t> values, std::span<const uint64_t> layout,
                                          std::span<const coding::BrickPlace> places = {}, bool labels = false,
                                          coding::BrickOrder order = coding::BrickOrder::Spatial, int model = coding::kLatestIntModel,
                                          int labelModel = 1, bool tileNeighbours = false, bool codeAside = false,
                                          std::span<const int32_t> reference = {});

// Inverse (`places` given exactly when the payload was coded with them);
// validates the payload against `layout` and `entries` (throws
// vdbdag::Error starting with `what`).
std::vector<uint8_t> decodeContextChannel(std::span<const uint8_t> payload, std::span<const uint64_t> layout, uint64_t entries, const std::string& what,
                                          std::span<const coding::BrickPlace> places = {}, bool labels = false,
                                          coding::BrickOrder order = coding::BrickOrder::Spatial, int model = coding::kLatestIntModel,
                                          int labelModel = 1, bool tileNeighbours = false, std::span<const int32_t> reference = {});

} // namespace vdbdag::attributes
