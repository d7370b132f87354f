// The compact, traceable encoding of an SSVDAG (SSVDAG paper §4.3). The
// exact word layout is documented at the top of CompactDag.cpp, beside the
// code that writes it. This is both the in-memory layout the tracers walk and
// (zstd-compressed) what the .ssvdag file stores.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "src/dag/ReducedDag.h"
#include "src/volume/GridTopology.h"

namespace vdbdag::encoding {

struct CompactDag {
    std::array<int64_t, 3> origin{0, 0, 0};  // index coordinate of the root cube's minimum corner
    uint8_t log2Size = 0;                    // 0: empty grid (no nodes at all)
    uint8_t rootReflection = 0;              // reflection applied to the root node
    // Start of each inner level in `inner` (16-bit words), root level first:
    // levelStart[i] holds nodes of size 2^(log2Size - i); log2Size - 2 entries.
    std::vector<uint64_t> levelStart;
    // Per inner level (root first): 16-bit words of each attribute offset
    // stored after a child pointer (0 = geometry only, no offsets).
    std::vector<uint8_t> offsetWords;
    std::vector<uint16_t> inner;   // all inner levels, root level first
    std::vector<uint64_t> leaves;  // 4^3 bricks, bit x + 4y + 16z

    bool empty() const { return log2Size == 0; }
    size_t innerLevelCount() const { return levelStart.size(); }
    uint64_t levelEnd(size_t i) const { return i + 1 < levelStart.size() ? levelStart[i + 1] : inner.size(); }
    uint64_t byteSize() const { return inner.size() * 2 + leaves.size() * 8 + levelStart.size() * 8; }
    // The same DAG, word for word (a 4-D scan's volumes: the same voxels).
    bool operator==(const CompactDag&) const = default;
};

// Lays out `dag` with the nodes of each level ordered by reference count
// (descending; ties by node index, so the result is deterministic). With
// `attributeOffsets`, every child pointer but a node's first carries the
// number of attribute entries of the preceding siblings (Dado et al. §4.1),
// in the smallest number of 16-bit words that fits the level. Throws
// vdbdag::Error if a pointer offset does not fit the 30-bit format.
// compactPointers = false writes every pointer in the 32-bit form (the
// "pointer compaction off" point of `vdbdag bench`; still a valid layout).
CompactDag encodeCompact(const dag::ReducedDag& dag, bool attributeOffsets = false, bool compactPointers = true);

// Checks that every header, pointer and offset is in range, that pointers
// land on node starts of the next level, that the root level holds one node
// and that every stored attribute offset equals the entries of the preceding
// siblings. Throws vdbdag::Error("<what>: ...").
void validateCompact(const CompactDag& dag, const std::string& what);

// At rest (docs/FORMAT.md 6.1-6.2) a level's attribute offsets are stored
// as 0: they are the entries of the preceding siblings, which a reader
// computes from the DAG below, so a file need not carry them (0.6-6.5 % of
// a level set's or fog's file, most of a label atlas's geometry). Its offset width in
// DagLevels then carries kOffsetsAtRest; a writer stores every level with
// offsets so, and an older file's stored offsets still read.
inline constexpr uint8_t kOffsetsAtRest = 0x80;
// The inner words and offset widths as a file stores them.
std::vector<uint16_t> innerWordsAtRest(const CompactDag& dag);
std::vector<uint8_t> offsetWordsAtRest(const CompactDag& dag);

// Decoded size, computed bottom-up without decoding (saturating at 2^64-1).
struct DecodedSize {
    uint64_t activeVoxels = 0;
    uint64_t emittedBricks = 0;     // bricks a decode emits
    uint64_t emittedTiles = 0;      // solid nodes (tiles) a decode emits
    uint64_t attributeEntries = 0;  // = voxels in bricks + tiles
};
DecodedSize decodedSize(const CompactDag& dag);

// A DAG as read, whose offset widths may carry kOffsetsAtRest: validated as
// validateCompact does (a flagged level's stored offsets must be 0), then
// the flagged levels' offsets are computed into `inner` and the flags
// cleared. Returns its decodedSize, from the same bottom-up pass. Throws
// vdbdag::Error("<what>: ...").
DecodedSize validateAndRestoreOffsets(CompactDag& dag, const std::string& what);

// Walks every instance of a validated DAG in attribute order: depth-first,
// children in the stored node's own slot order, with the reflections
// accumulated on the way down (DESIGN.md invariant 2). For a brick the
// callback gets the stored mask and the accumulated reflection: its
// attribute entries are the stored mask's set bits in increasing order,
// stored bit b being the voxel at reflect(mirror, b). A solid node (tile) is
// one entry. `firstEntry` is the index of the instance's first entry.
struct BrickInstance {
    int64_t x, y, z;       // minimum corner (index space)
    unsigned mirror;       // accumulated reflection
    uint64_t storedMask;   // the leaf as stored
    uint64_t firstEntry;
    uint64_t spatialMask() const;
};
using BrickInstanceVisitor = std::function<void(const BrickInstance&)>;
using SolidVisitor = std::function<void(int64_t x, int64_t y, int64_t z, unsigned log2Size, uint64_t entry)>;
void visitInAttributeOrder(const CompactDag& dag, const BrickInstanceVisitor& brick, const SolidVisitor& solid);

// The same walk cut into subtrees (for encoders that gather values one cube
// at a time): the instances of nodes of 2^log2Size voxels, and of solid
// nodes at or above that size, in attribute order. A subtree's entries are
// contiguous, starting at firstEntry.
struct SubtreeInstance {
    unsigned level;        // inner level index (0 = root level)
    uint64_t offset;       // word offset of the node within its level
    unsigned mirror;       // accumulated reflection
    int64_t x, y, z;       // minimum corner (index space)
    unsigned log2Size;
    uint64_t firstEntry;
    bool solid;            // a solid node (tile): one entry
};
std::vector<SubtreeInstance> subtreesInAttributeOrder(const CompactDag& dag, unsigned log2Size);
// visitInAttributeOrder restricted to one such subtree (entries numbered
// from its firstEntry).
void visitSubtreeInAttributeOrder(const CompactDag& dag, const SubtreeInstance& root, const BrickInstanceVisitor& brick,
                                  const SolidVisitor& solid);

// Geometry-only convenience over visitInAttributeOrder.
using BrickVisitor = std::function<void(int64_t x, int64_t y, int64_t z, uint64_t mask)>;
using TileVisitor = std::function<void(int64_t x, int64_t y, int64_t z, unsigned log2Size)>;
void visitInstances(const CompactDag& dag, const BrickVisitor& brick, const TileVisitor& tile);

// Convenience: the whole topology (tiles as tiles). Coordinates must fit int32.
GridTopology decodeTopology(const CompactDag& dag);

// Parsing helpers shared with the tracers (the words themselves are decoded
// by include/vdbdag/dag_access.h; the loops over a whole DAG are
// DagDescent.h's).
struct ChildPointer {
    uint64_t offset;           // in words of the next level (16-bit inner / 64-bit leaf words)
    unsigned reflection;
    uint64_t attributeOffset;  // entries of the preceding stored siblings (0 without offsets)
};
// Number of 16-bit words a node occupies, from its header; a header of 0 is
// a solid node (one word).
unsigned nodeWordCount(uint16_t header, unsigned offsetWords);
// Reads the child of stored slot j of the node whose header is at inner[pos].
ChildPointer readChild(const std::vector<uint16_t>& inner, uint64_t pos, unsigned j, unsigned offsetWords);

} // namespace vdbdag::encoding
