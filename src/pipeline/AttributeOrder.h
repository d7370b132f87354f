// Moving values between input order (per brick, increasing spatial bit) and
// attribute order (the DAG's depth-first order as stored, DESIGN.md
// invariant 2): gather when encoding, scatter when decoding. Both walk the
// compact DAG with visitInAttributeOrder, so the order the tracers use and
// the order the file stores are the same by construction.
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "src/coding/BrickValueCoder.h"
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
// With `layout`, appends the subtree's part of encoding::attributeLayout
// (per brick instance its stored mask, 0 per solid node) to it, and with
// `places` its part of encoding::attributePlaces.
void gatherSubtree(const encoding::CompactDag& dag, const encoding::SubtreeInstance& subtree, const GridTopology& topology,
                   const LayerValues& values, unsigned valueSize, uint8_t* buffer, uint64_t bufferFirstEntry = 0,
                   std::vector<uint64_t>* layout = nullptr, std::vector<coding::BrickPlace>* places = nullptr);

// One subtree's voxels with their values, for readers that stream a layer:
// `values` holds its entries (entry e at (e - subtree.firstEntry) *
// valueSize; unused when valueSize is 0). A brick comes with its spatial
// mask and its values in increasing spatial bit order; a solid node with
// its size and value.
struct SubtreeVoxels {
    std::function<void(int64_t x, int64_t y, int64_t z, uint64_t spatialMask, const uint8_t* values)> brick;
    std::function<void(int64_t x, int64_t y, int64_t z, unsigned log2Size, const uint8_t* value)> solid;
};
void scatterSubtree(const encoding::CompactDag& dag, const encoding::SubtreeInstance& subtree, const uint8_t* values, unsigned valueSize,
                    const SubtreeVoxels& visit);

// Attribute-order values -> the decoded topology and its values in input order.
void scatterAttributes(const encoding::CompactDag& dag, const std::vector<uint8_t>& attributes, unsigned valueSize,
                       GridTopology& topology, LayerValues& values);

} // namespace vdbdag::pipeline
