// The shape of a DAG's attribute array, for coders that need the neighbours
// of an entry (attributes/PredictedChannel.h): per brick instance in
// attribute order (DESIGN.md invariant 2) its stored mask, 0 for a solid node
// (one entry). Only the stored masks are needed, never positions, because a
// reflected instance reads its entries in the stored brick's own frame.
#pragma once
#include <cstdint>
#include <vector>

#include "src/coding/BrickValueCoder.h"
#include "src/encoding/CompactDag.h"

namespace vdbdag::encoding {

std::vector<uint64_t> attributeLayout(const CompactDag& dag);

// Where each entry of attributeLayout lies (its minimum corner, the mirror
// accumulated down to it; a solid node's place is zero): what the value
// coder of int32 windows needs for neighbours across bricks
// (coding/BrickValueCoder.h). Empty unless `valueSize` is 4: only int32
// windows and rescaled float32 ones use them.
std::vector<coding::BrickPlace> attributePlaces(const CompactDag& dag, uint32_t valueSize);

} // namespace vdbdag::encoding
