// Moving values between input order (per brick, increasing spatial bit) and
// attribute order (the DAG's depth-first order as stored, DESIGN.md
// invariant 2): gather when encoding, scatter when decoding. Both walk the
// compact DAG with visitInAttributeOrder, so the order the tracers use and
// the order the file stores are the same by construction.
#pragma once
#include <cstdint>
#include <vector>

#include "src/encoding/CompactDag.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::pipeline {

// Values of `topology` (input order) -> attribute order of `dag`, which must
// encode exactly that topology.
std::vector<uint8_t> gatherAttributes(const encoding::CompactDag& dag, const GridTopology& topology, const LayerValues& values,
                                      unsigned valueSize);

// The same for one subtree (encoding::subtreesInAttributeOrder) and the
// part of the input inside it: writes the subtree's entries into `buffer`,
// which holds the attribute array's entries from `bufferFirstEntry` on.
void gatherSubtree(const encoding::CompactDag& dag, const encoding::SubtreeInstance& subtree, const GridTopology& topology,
                   const LayerValues& values, unsigned valueSize, uint8_t* buffer, uint64_t bufferFirstEntry = 0);

// Attribute-order values -> the decoded topology and its values in input order.
void scatterAttributes(const encoding::CompactDag& dag, const std::vector<uint8_t>& attributes, unsigned valueSize,
                       GridTopology& topology, LayerValues& values);

} // namespace vdbdag::pipeline
