// Compact SSVDAG encoding (SSVDAG paper §4.3): writer, validator, walker.
//
// Layout (all little-endian):
//
//   inner  : uint16 words. The inner levels one after another, root level
//            first; level i (nodes 2^(log2Size-i) voxels wide) starts at word
//            levelStart[i]. The root level holds exactly one node, at its
//            word 0. Within a level, nodes are sorted by reference count,
//            most referenced first (ties: builder order), so the most shared
//            nodes get the short pointers.
//   node   : word 0 is the header: bits 2j..2j+1 hold the tag of stored child
//            slot j (slot = x | y<<1 | z<<2 within the node):
//              00  no child (nothing stored)
//              01  16-bit pointer: one word  [mmm ooooooooooooo]
//                  m = 3 reflection bits (bit 13: x, 14: y, 15: z),
//                  o = 13-bit offset
//              1b  32-bit pointer: two words [mmm oooooooooooooo][oooooooooooooooo]
//                  first word: reflection in bits 13..15, offset bits 16..28
//                  in its low 13 bits; second word: offset bits 0..15;
//                  offset bit 29 = b, the low bit of the tag.
//            followed by the pointers of the present children in slot order.
//            Offsets count words from the start of the next level: 16-bit
//            words for an inner level, 64-bit words (= leaf index) for the
//            leaf level. So offsets reach 2^30 words (2 GiB of inner level,
//            8 GiB of leaves); an encoder that would need more stops with an
//            error instead of writing a corrupt node.
//   leaves : uint64 per 4^3 brick, bit x + 4y + 16z.
//
// A child instance is the stored node reflected by the pointer's reflection
// composed (XOR) with the reflections above it. A traversal that is at
// spatial child slot p under accumulated reflection m reads stored slot p^m;
// in a leaf it reads bit mirror(m, voxel) (DESIGN.md invariant 2).
#include "src/encoding/CompactDag.h"

#include <algorithm>
#include <bit>
#include <limits>
#include <numeric>

#include "src/dag/Reflection.h"
#include "src/util/Error.h"

namespace vdbdag::encoding {
namespace {

constexpr uint64_t kShortOffsetLimit = uint64_t(1) << 13;
constexpr uint64_t kLongOffsetLimit = uint64_t(1) << 30;
constexpr unsigned kMaxLog2Size = 40;
constexpr uint64_t kMaxEmittedPieces = uint64_t(1) << 31;

// Node indices of a level ordered by reference count, most referenced first.
template <typename Refcounts>
std::vector<uint32_t> frequencyOrder(const Refcounts& refcount) {
    std::vector<uint32_t> order;
    order.reserve(refcount.size());
    for (uint32_t i = 0; i < refcount.size(); ++i)
        if (refcount[i] > 0) order.push_back(i);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return refcount[a] > refcount[b]; });
    return order;
}

unsigned tagWords(unsigned tag) { return tag == 0 ? 0 : tag == 1 ? 1 : 2; }

uint64_t saturatingAdd(uint64_t a, uint64_t b) { return a > std::numeric_limits<uint64_t>::max() - b ? std::numeric_limits<uint64_t>::max() : a + b; }

// Reads the pointer of stored slot j of the node whose header is at inner[pos].
ChildPointer readPointer(const std::vector<uint16_t>& inner, uint64_t pos, unsigned j) {
    const uint16_t header = inner[pos];
    uint64_t at = pos + 1;
    for (unsigned k = 0; k < j; ++k) at += tagWords((header >> (2 * k)) & 3u);
    const unsigned tag = (header >> (2 * j)) & 3u;
    const uint16_t w0 = inner[at];
    if (tag == 1) return {uint64_t(w0 & 0x1FFFu), unsigned(w0 >> 13)};
    const uint64_t offset = (uint64_t(tag & 1u) << 29) | (uint64_t(w0 & 0x1FFFu) << 16) | inner[at + 1];
    return {offset, unsigned(w0 >> 13)};
}

} // namespace

unsigned nodeWordCount(uint16_t header) {
    unsigned words = 1;
    for (unsigned j = 0; j < 8; ++j) words += tagWords((header >> (2 * j)) & 3u);
    return words;
}

CompactDag encodeCompact(const dag::ReducedDag& dag) {
    CompactDag out;
    if (dag.empty()) return out;
    out.origin = dag.origin;
    out.log2Size = uint8_t(dag.log2Size);
    out.rootReflection = uint8_t(dag::childReflection(dag.root));

    // Leaves: position = word offset.
    std::vector<uint64_t> position(dag.bricks.size(), std::numeric_limits<uint64_t>::max());
    for (uint32_t index : frequencyOrder(dag.brickRefcount)) {
        position[index] = out.leaves.size();
        out.leaves.push_back(dag.bricks[index]);
    }
    // Inner levels bottom-up, so each knows where its children landed.
    std::vector<std::vector<uint16_t>> levels(dag.inner.size());
    for (size_t k = 0; k < dag.inner.size(); ++k) {
        const dag::InnerLevel& level = dag.inner[k];
        std::vector<uint16_t>& words = levels[k];
        std::vector<uint64_t> here(level.nodes.size(), std::numeric_limits<uint64_t>::max());
        for (uint32_t index : frequencyOrder(level.refcount)) {
            here[index] = words.size();
            const size_t headerAt = words.size();
            words.push_back(0);
            uint16_t header = 0;
            for (unsigned j = 0; j < 8; ++j) {
                const dag::ChildRef child = level.nodes[index][j];
                if (!child) continue;
                const uint64_t offset = position[dag::childIndex(child)];
                const uint16_t mirror = uint16_t(dag::childReflection(child) << 13);
                if (offset < kShortOffsetLimit) {
                    header |= uint16_t(1u << (2 * j));
                    words.push_back(uint16_t(mirror | offset));
                } else if (offset < kLongOffsetLimit) {
                    header |= uint16_t((2u | unsigned(offset >> 29)) << (2 * j));
                    words.push_back(uint16_t(mirror | ((offset >> 16) & 0x1FFFu)));
                    words.push_back(uint16_t(offset & 0xFFFFu));
                } else {
                    throw Error("DAG level " + std::to_string(k + 3) + " needs a child offset of " + std::to_string(offset) +
                                " words, beyond the 30-bit pointer format (2^30 words)");
                }
            }
            words[headerAt] = header;
        }
        position = std::move(here);
    }
    // Concatenate, root level first.
    for (size_t k = levels.size(); k-- > 0;) {
        out.levelStart.push_back(out.inner.size());
        out.inner.insert(out.inner.end(), levels[k].begin(), levels[k].end());
    }
    return out;
}

void validateCompact(const CompactDag& dag, const std::string& what) {
    auto fail = [&](const std::string& why) { throw Error(what + ": " + why); };
    if (dag.log2Size == 0) {
        if (!dag.levelStart.empty() || !dag.inner.empty() || !dag.leaves.empty()) fail("an empty grid must have no nodes");
        return;
    }
    if (dag.log2Size < 3 || dag.log2Size > kMaxLog2Size) fail("root size 2^" + std::to_string(dag.log2Size) + " out of range");
    if (dag.rootReflection > 7) fail("bad root reflection");
    const size_t levels = dag.innerLevelCount();
    if (levels != size_t(dag.log2Size) - 2) fail("level table has " + std::to_string(levels) + " levels, expected " + std::to_string(dag.log2Size - 2));
    if (dag.levelStart[0] != 0) fail("root level does not start at word 0");
    for (size_t i = 0; i < levels; ++i)
        if (dag.levelStart[i] >= dag.levelEnd(i)) fail("inner level " + std::to_string(i) + " is empty or out of order");
    for (size_t i = 0; i < dag.leaves.size(); ++i)
        if (dag.leaves[i] == 0) fail("leaf " + std::to_string(i) + " is empty");

    // Pass 1: node boundaries of every level.
    std::vector<std::vector<uint8_t>> isNodeStart(levels);
    for (size_t i = 0; i < levels; ++i) {
        const uint64_t begin = dag.levelStart[i], end = dag.levelEnd(i);
        isNodeStart[i].assign(end - begin, 0);
        uint64_t nodes = 0;
        for (uint64_t pos = begin; pos < end; ++nodes) {
            const uint16_t header = dag.inner[pos];
            if (header == 0) fail("node at word " + std::to_string(pos) + " has no children");
            const unsigned words = nodeWordCount(header);
            if (words > end - pos) fail("node at word " + std::to_string(pos) + " runs past the end of its level");
            isNodeStart[i][pos - begin] = 1;
            pos += words;
        }
        if (i == 0 && nodes != 1) fail("root level holds " + std::to_string(nodes) + " nodes, expected 1");
    }
    // Pass 2: every pointer lands on a node of the next level (or a leaf).
    for (size_t i = 0; i < levels; ++i) {
        const uint64_t begin = dag.levelStart[i], end = dag.levelEnd(i);
        const bool toLeaves = i + 1 == levels;
        for (uint64_t pos = begin; pos < end; pos += nodeWordCount(dag.inner[pos])) {
            const uint16_t header = dag.inner[pos];
            for (unsigned j = 0; j < 8; ++j) {
                if (((header >> (2 * j)) & 3u) == 0) continue;
                const ChildPointer p = readPointer(dag.inner, pos, j);
                const bool ok = toLeaves ? p.offset < dag.leaves.size()
                                         : p.offset < isNodeStart[i + 1].size() && isNodeStart[i + 1][p.offset];
                if (!ok) fail("pointer at level " + std::to_string(i) + " word " + std::to_string(pos) + " targets " +
                              std::to_string(p.offset) + ", which is not a node of the next level");
            }
        }
    }
}

namespace {

// Per-node facts computed bottom-up over the stored (unmirrored) nodes;
// reflections change neither voxel counts nor fullness.
struct NodeFacts {
    std::vector<uint8_t> full;           // per inner word offset of the level: node there is fully active
    std::vector<uint64_t> voxels;        // per inner word offset (only node starts are meaningful)
    std::vector<uint64_t> bricks, tiles; // emitted by a decode of this node
};

std::vector<NodeFacts> computeFacts(const CompactDag& dag) {
    const size_t levels = dag.innerLevelCount();
    std::vector<NodeFacts> facts(levels);
    const unsigned leafLevel = 2;
    for (size_t i = levels; i-- > 0;) {
        const uint64_t begin = dag.levelStart[i], end = dag.levelEnd(i);
        NodeFacts& f = facts[i];
        f.full.assign(end - begin, 0);
        f.voxels.assign(end - begin, 0);
        f.bricks.assign(end - begin, 0);
        f.tiles.assign(end - begin, 0);
        const unsigned childLog2 = dag.log2Size - unsigned(i) - 1;
        for (uint64_t pos = begin; pos < end; pos += nodeWordCount(dag.inner[pos])) {
            const uint16_t header = dag.inner[pos];
            uint64_t voxels = 0, bricks = 0, tiles = 0;
            bool full = true;
            for (unsigned j = 0; j < 8; ++j) {
                if (((header >> (2 * j)) & 3u) == 0) { full = false; continue; }
                const ChildPointer p = readPointer(dag.inner, pos, j);
                if (childLog2 == leafLevel) {
                    const uint64_t leaf = dag.leaves[p.offset];
                    voxels += uint64_t(std::popcount(leaf));
                    bricks += 1;
                    full = full && leaf == ~uint64_t(0);
                } else {
                    const NodeFacts& c = facts[i + 1];
                    voxels = saturatingAdd(voxels, c.voxels[p.offset]);
                    if (c.full[p.offset]) {
                        tiles += 1;
                    } else {
                        bricks = saturatingAdd(bricks, c.bricks[p.offset]);
                        tiles = saturatingAdd(tiles, c.tiles[p.offset]);
                        full = false;
                    }
                }
            }
            f.full[pos - begin] = full;
            f.voxels[pos - begin] = voxels;
            f.bricks[pos - begin] = bricks;
            f.tiles[pos - begin] = tiles;
        }
    }
    return facts;
}

} // namespace

DecodedSize decodedSize(const CompactDag& dag) {
    if (dag.empty()) return {};
    const auto facts = computeFacts(dag);
    const NodeFacts& root = facts[0];
    if (root.full[0]) return {root.voxels[0], 0, 1};
    return {root.voxels[0], root.bricks[0], root.tiles[0]};
}

void visitInstances(const CompactDag& dag, const BrickVisitor& brick, const TileVisitor& tile) {
    if (dag.empty()) return;
    const auto facts = computeFacts(dag);

    struct Walker {
        const CompactDag& dag;
        const std::vector<NodeFacts>& facts;
        const BrickVisitor& brick;
        const TileVisitor& tile;
        uint64_t emitted = 0;

        void count() {
            if (++emitted > kMaxEmittedPieces)
                throw Error("decoding would create more than 2^31 bricks and tiles: the grid is implausibly large to decode here");
        }
        // A fully active cube: a tile where OpenVDB-style alignment allows
        // (position a multiple of the size), else split into its children.
        void full(int64_t x, int64_t y, int64_t z, unsigned log2Size) {
            const int64_t size = int64_t(1) << log2Size;
            if (log2Size == 2) { count(); brick(x, y, z, ~uint64_t(0)); return; }
            if ((x & (size - 1)) == 0 && (y & (size - 1)) == 0 && (z & (size - 1)) == 0) { count(); tile(x, y, z, log2Size); return; }
            const int64_t half = size / 2;
            for (unsigned p = 0; p < 8; ++p) full(x + ((p & 1u) ? half : 0), y + ((p & 2u) ? half : 0), z + ((p & 4u) ? half : 0), log2Size - 1);
        }
        void visit(size_t i, uint64_t offset, unsigned mirror, int64_t x, int64_t y, int64_t z) {
            const unsigned log2Size = dag.log2Size - unsigned(i);
            if (facts[i].full[offset]) { full(x, y, z, log2Size); return; }
            const uint64_t pos = dag.levelStart[i] + offset;
            const uint16_t header = dag.inner[pos];
            const int64_t half = int64_t(1) << (log2Size - 1);
            const bool toLeaves = i + 1 == dag.innerLevelCount();
            for (unsigned p = 0; p < 8; ++p) {  // spatial slot
                const unsigned j = p ^ mirror;  // stored slot
                if (((header >> (2 * j)) & 3u) == 0) continue;
                const ChildPointer ptr = readPointer(dag.inner, pos, j);
                const unsigned childMirror = mirror ^ ptr.reflection;
                const int64_t cx = x + ((p & 1u) ? half : 0), cy = y + ((p & 2u) ? half : 0), cz = z + ((p & 4u) ? half : 0);
                if (toLeaves) {
                    count();
                    brick(cx, cy, cz, dag::reflectBrick(dag.leaves[ptr.offset], childMirror));
                } else {
                    visit(i + 1, ptr.offset, childMirror, cx, cy, cz);
                }
            }
        }
    };
    Walker{dag, facts, brick, tile}.visit(0, 0, dag.rootReflection, dag.origin[0], dag.origin[1], dag.origin[2]);
}

GridTopology decodeTopology(const CompactDag& dag) {
    GridTopology topology;
    const DecodedSize size = decodedSize(dag);
    topology.bricks.reserve(size.emittedBricks);
    auto toInt32 = [](int64_t v) {
        if (v < std::numeric_limits<int32_t>::min() || v > std::numeric_limits<int32_t>::max())
            throw Error("decoded coordinate " + std::to_string(v) + " is outside OpenVDB's int32 index range");
        return int32_t(v);
    };
    visitInstances(
        dag, [&](int64_t x, int64_t y, int64_t z, uint64_t mask) { topology.bricks.push_back({toInt32(x), toInt32(y), toInt32(z), mask}); },
        [&](int64_t x, int64_t y, int64_t z, unsigned log2Size) {
            topology.tiles.push_back({toInt32(x), toInt32(y), toInt32(z), uint8_t(log2Size)});
        });
    return topology;
}

} // namespace vdbdag::encoding
