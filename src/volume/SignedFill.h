// A level set's inactive values as OpenVDB's tools::signedFloodFill makes
// them, computed from its active voxels alone (issue 40 item 3: a level
// set's inactive values should cost nothing beyond their sign, which the
// active values imply).
//
// signedFloodFill gives every inactive value of a tree -|background|
// (inside) or +|background| (outside) by propagating the sign of the
// active values along the index order of each node, bottom-up:
//   - a leaf (8^3): along z, then y, then x, each inactive voxel takes the
//     sign of the last voxel before it in its column (x, y, 0..z-1) that is
//     active, else that of (x, y, 0)'s row start, else of (x, 0, 0), else of
//     the leaf's first active voxel;
//   - an internal node (16^3 slots of 8^3, then 32^3 slots of 128^3): the
//     same over its slots, a child slot giving the sign of the child's last
//     value (its first value for the scan's start), a tile slot taking one;
//   - the root: a run of missing 4096^3 nodes along z between two nodes
//     whose facing values (the last of the lower, the first of the upper)
//     are inside becomes inside tiles.
// Outside values equal the background and are not stored; the inside ones
// are the grid's inactive layer (GridRecord::inactiveTopology).
//
// signedFillInactive computes that layer for OpenVDB's standard tree
// (5, 4, 3) holding exactly the nodes that the active voxels need. A file
// whose inactive layer equals it can drop the layer and have the reader
// make it again (the encoder compares the two; they differ where the
// file's tree held other nodes or other values).
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include "src/volume/GridRecord.h"

namespace vdbdag {

// The fill in pieces, for a source that reads a grid leaf by leaf (the
// encoder's check, vdb_bridge/VdbCubes.cpp): each leaf alone (fillLeaf),
// then the tiles above the leaves from each leaf's first and last values.
class SignedFillTree {
public:
    using Origin = std::array<int32_t, 3>;
    // Leaf voxels by OpenVDB's index n = x << 6 | y << 3 | z (x, y, z in
    // 0..7): bit n & 63 of word n >> 6 (word x holds y << 3 | z).
    static size_t leafIndex(unsigned x, unsigned y, unsigned z) { return size_t(x) << 6 | size_t(y) << 3 | size_t(z); }
    using LeafBits = std::array<uint64_t, 8>;
    static void set(LeafBits& bits, size_t n) { bits[n >> 6] |= uint64_t(1) << (n & 63); }
    static bool test(const LeafBits& bits, size_t n) { return (bits[n >> 6] >> (n & 63)) & 1; }
    struct LeafFill {
        LeafBits inside{};  // the inactive voxels the fill makes inside
        bool first = false, last = false;  // whether the leaf's values at index 0 and 511 are then negative
    };
    // One leaf with at least one active voxel: which are active and which
    // of their values are negative.
    static LeafFill fillLeaf(const LeafBits& active, const LeafBits& negative);
    // Each leaf once (its origin a multiple of 8), in any order.
    void addLeaf(const Origin& origin, const LeafFill& fill);
    // The inside tiles: 8^3 and 128^3 tiles of the internal nodes, then the
    // root's 4096^3 ones, in a fixed order.
    std::vector<Tile> insideTiles() const;

private:
    std::map<Origin, std::pair<bool, bool>> leaves_;  // first, last
};

struct InactiveLayer {
    GridTopology topology;  // inside voxels (bricks) and inside tiles (8^3, 128^3, 4096^3)
    LayerValues values;     // -|background| each, in the order of the bricks' bits, then of the tiles
};

// The inactive layer signedFloodFill gives the active voxels `active` with
// values `values` (GridRecord's order) of a float or double grid with
// `background` (its bytes). nullopt where it does not apply: another value
// type, a background that is not a positive finite number, or active tiles
// (signedFloodFill would overwrite their values).
// `parallel(n, body)` runs body(0 .. n-1) in any order (the leaves, each
// alone); empty: one after another. The result is the same either way.
using FillParallel = std::function<void(size_t n, const std::function<void(size_t)>& body)>;
std::optional<InactiveLayer> signedFillInactive(const GridTopology& active, const LayerValues& values, ValueType type,
                                                std::span<const uint8_t> background, const FillParallel& parallel = {});

// Whether two inactive layers hold the same voxels and tiles with the same
// value bits, whatever their order.
bool sameInactiveLayer(const GridTopology& a, const LayerValues& aValues, const GridTopology& b, const LayerValues& bValues, ValueType type);

} // namespace vdbdag
