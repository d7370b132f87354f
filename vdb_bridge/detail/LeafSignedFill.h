// Whether an OpenVDB leaf's inactive values are the signed flood fill of its
// active ones (src/volume/SignedFill.h, what tools::signedFloodFill leaves in
// a level set): the check VdbCubes makes of every leaf before it stores a
// grid's inactive layer as an InactiveSignedFill section instead of values.
#pragma once
#include <cstdint>

#include <openvdb/openvdb.h>

#include "src/volume/SignedFill.h"
#include "vdb_bridge/detail/LeafBricks.h"

namespace vdbdag::bridge::detail {

// Bit 0 set when every inactive value of `leaf` is its fill (-|background|
// inside, the background outside); bits 1 and 2 the signs of its first and
// last values (for the fill of the nodes above). 0 for a leaf without active
// values: the fill of such a leaf reads what it overwrites.
template <typename LeafT>
uint8_t leafSignedFill(const LeafT& leaf, typename LeafT::ValueType background) {
    using ValueT = typename LeafT::ValueType;
    const ValueT* data = leaf.buffer().data();
    SignedFillTree::LeafBits active{}, negative{};  // the value mask's words are LeafBits' (bit n & 63 of word n >> 6)
    for (unsigned w = 0; w < 8; ++w) active[w] = leaf.getValueMask().template getWord<uint64_t>(w);
    for (openvdb::Index n = 0; n < LeafT::SIZE; ++n)
        if (SignedFillTree::test(active, n) && data[n] < ValueT(0)) SignedFillTree::set(negative, n);
    if (active == SignedFillTree::LeafBits{}) return 0;
    const SignedFillTree::LeafFill fill = SignedFillTree::fillLeaf(active, negative);
    const ValueT inside = -background;
    for (openvdb::Index n = 0; n < LeafT::SIZE; ++n)
        if (!SignedFillTree::test(active, n) && !sameBits(data[n], SignedFillTree::test(fill.inside, n) ? inside : background)) return 0;
    return uint8_t(1u | unsigned(fill.first) << 1 | unsigned(fill.last) << 2);
}

} // namespace vdbdag::bridge::detail
