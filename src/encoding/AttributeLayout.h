// The shape of a DAG's attribute array, for coders that need the neighbours
// of an entry (attributes/PredictedChannel.h): per brick instance in
// attribute order (DESIGN.md invariant 2) its stored mask, 0 for a solid node
// (one entry). Only the stored masks are needed, never positions, because a
// reflected instance reads its entries in the stored brick's own frame.
#pragma once
#include <cstdint>
#include <vector>

#include "src/encoding/CompactDag.h"

namespace vdbdag::encoding {

std::vector<uint64_t> attributeLayout(const CompactDag& dag);

} // namespace vdbdag::encoding
