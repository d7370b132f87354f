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
//   node   : word 0 is the header. A header of 0 is a solid node: the whole
//            cube is active and carries ONE attribute entry (an OpenVDB
//            active tile; never expanded). Otherwise bits 2j..2j+1 hold the
//            tag of stored child slot j (slot = x | y<<1 | z<<2):
//              00  no child (nothing stored)
//              01  16-bit pointer: one word  [mmm ooooooooooooo]
//                  m = 3 reflection bits (bit 13: x, 14: y, 15: z),
//                  o = 13-bit offset
//              1b  32-bit pointer: two words [mmm oooooooooooooo][oooooooooooooooo]
//                  first word: reflection in bits 13..15, offset bits 16..28
//                  in its low 13 bits; second word: offset bits 0..15;
//                  offset bit 29 = b, the low bit of the tag.
//            followed by the present children in slot order: each child's
//            pointer, then, for every child but the first, its attribute
//            offset in offsetWords[level] 16-bit words (low word first): the
//            attribute entries of the preceding present siblings (Dado et
//            al. §4.1). offsetWords is 0 for geometry-only grids.
//            Offsets count words from the start of the next level: 16-bit
//            words for an inner level, 64-bit words (= leaf index) for the
//            leaf level. So offsets reach 2^30 words (2 GiB of inner level,
//            8 GiB of leaves); an encoder that would need more stops with an
//            error instead of writing a corrupt node.
//   leaves : uint64 per 4^3 brick, bit x + 4y + 16z.
//
// Attribute entries of a node: popcount for a leaf, 1 for a solid node, the
// sum over its children otherwise. A child instance is the stored node
// reflected by the pointer's reflection
// composed (XOR) with the reflections above it. A traversal that is at
// spatial child slot p under accumulated reflection m reads stored slot p^m;
// in a leaf it reads bit mirror(m, voxel) (DESIGN.md invariant 2).
#include "src/encoding/CompactDag.h"
#include "src/encoding/DagDescent.h"

#include <vdbdag/dag_access.h>

#include <algorithm>
#include <bit>
#include <limits>
#include <numeric>

#include "src/dag/Reflection.h"
#include "src/util/Error.h"

namespace vdbdag::encoding {
namespace {

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


uint64_t saturatingAdd(uint64_t a, uint64_t b) { return a > std::numeric_limits<uint64_t>::max() - b ? std::numeric_limits<uint64_t>::max() : a + b; }

} // namespace

unsigned nodeWordCount(uint16_t header, unsigned offsetWords) { return access::dagNodeWords(header, offsetWords); }

ChildPointer readChild(const std::vector<uint16_t>& inner, uint64_t pos, unsigned j, unsigned offsetWords) {
    ChildPointer child{};
    access::dagChildPointer(inner.data(), pos, inner[pos], j, offsetWords, child.offset, child.reflection, child.attributeOffset);
    return child;
}

CompactDag encodeCompact(const dag::ReducedDag& dag, bool attributeOffsets, bool compactPointers) {
    CompactDag out;
    if (dag.empty()) return out;
    out.origin = dag.origin;
    out.log2Size = uint8_t(dag.log2Size);
    out.rootReflection = uint8_t(dag::childReflection(dag.root));

    // Leaves: position = word offset.
    std::vector<uint64_t> position(dag.bricks.size(), std::numeric_limits<uint64_t>::max());
    std::vector<uint64_t> entries(dag.bricks.size());
    for (size_t i = 0; i < dag.bricks.size(); ++i) entries[i] = uint64_t(std::popcount(dag.bricks[i]));
    for (uint32_t index : frequencyOrder(dag.brickRefcount)) {
        position[index] = out.leaves.size();
        out.leaves.push_back(dag.bricks[index]);
    }
    // Inner levels bottom-up, so each knows where its children landed.
    std::vector<std::vector<uint16_t>> levels(dag.inner.size());
    std::vector<uint8_t> offsetWords(dag.inner.size(), 0);
    for (size_t k = 0; k < dag.inner.size(); ++k) {
        const dag::InnerLevel& level = dag.inner[k];
        // Attribute entries per node, and the widest offset this level stores.
        std::vector<uint64_t> here(level.nodes.size(), std::numeric_limits<uint64_t>::max());
        std::vector<uint64_t> nodeEntries(level.nodes.size(), 0);
        uint64_t widest = 0;
        bool anySibling = false;
        for (size_t n = 0; n < level.nodes.size(); ++n) {
            uint64_t sum = 0;
            unsigned children = 0;
            for (dag::ChildRef c : level.nodes[n]) {
                if (!c) continue;
                if (children++ > 0) { widest = std::max(widest, sum); anySibling = true; }
                sum = saturatingAdd(sum, entries[dag::childIndex(c)]);
            }
            nodeEntries[n] = children == 0 ? 1 : sum;  // a solid node is one entry
        }
        if (attributeOffsets && anySibling) offsetWords[k] = uint8_t(std::max<uint64_t>(1, (std::bit_width(widest) + 15) / 16));
        const unsigned ow = offsetWords[k];
        std::vector<uint16_t>& words = levels[k];
        for (uint32_t index : frequencyOrder(level.refcount)) {
            here[index] = words.size();
            const size_t headerAt = words.size();
            words.push_back(0);
            uint16_t header = 0;
            uint64_t preceding = 0;
            bool first = true;
            for (unsigned j = 0; j < 8; ++j) {
                const dag::ChildRef child = level.nodes[index][j];
                if (!child) continue;
                const uint64_t offset = position[dag::childIndex(child)];
                const unsigned tag = access::dagPointerTag(offset, compactPointers);
                if (tag == 0)
                    throw Error("DAG level " + std::to_string(k + 3) + " needs a child offset of " + std::to_string(offset) +
                                " words, beyond the 30-bit pointer format (2^30 words)");
                header |= uint16_t(tag << (2 * j));
                words.push_back(uint16_t(access::dagPointerWord0(offset, unsigned(dag::childReflection(child)), tag)));
                if (tag != 1) words.push_back(uint16_t(access::dagPointerWord1(offset)));
                if (!first)
                    for (unsigned w = 0; w < ow; ++w) words.push_back(uint16_t(preceding >> (16 * w)));
                first = false;
                preceding += entries[dag::childIndex(child)];
            }
            words[headerAt] = header;
        }
        position = std::move(here);
        entries = std::move(nodeEntries);
    }
    // Concatenate, root level first.
    for (size_t k = levels.size(); k-- > 0;) {
        out.levelStart.push_back(out.inner.size());
        out.offsetWords.push_back(offsetWords[k]);
        out.inner.insert(out.inner.end(), levels[k].begin(), levels[k].end());
    }
    return out;
}

namespace {

// What a stored (unmirrored) node holds, computed bottom-up; reflections
// change none of it.
struct NodeFact {
    uint64_t voxels = 0, entries = 0, bricks = 0, tiles = 0;
};

// One level's facts, a row per node, found by the node's first word within
// the level. The rows are per node and the index 4 bytes a word: rows of
// 32 bytes a word, as before, made every walk in attribute order zero 42 MB
// for the d=1024 sphere's 1.3M words of DAG, and the encoder walks it
// several times (decodedSize, subtreesInAttributeOrder, ...).
struct NodeFacts {
    std::vector<uint32_t> row;  // by word within the level; set at node starts only
    std::vector<NodeFact> rows;
    const NodeFact& operator[](uint64_t word) const { return rows[row[size_t(word)]]; }
};

} // namespace

namespace {

// validateCompact, where a level whose atRest flag is set must store every
// attribute offset as 0 (its offsets are then filled in by the caller).
void checkCompact(const CompactDag& dag, const std::string& what, const std::vector<uint8_t>& atRest) {
    auto fail = [&](const std::string& why) { throw Error(what + ": " + why); };
    if (dag.log2Size == 0) {
        if (!dag.levelStart.empty() || !dag.inner.empty() || !dag.leaves.empty() || !dag.offsetWords.empty()) fail("an empty grid must have no nodes");
        return;
    }
    if (dag.log2Size < 3 || dag.log2Size > kMaxLog2Size) fail("root size 2^" + std::to_string(dag.log2Size) + " out of range");
    if (dag.rootReflection > 7) fail("bad root reflection");
    // The root's origin is an index of OpenVDB's int32 range; with at most
    // 2^40 voxels per side no coordinate arithmetic of the walkers overflows
    // (each voxel's own index is checked where it is decoded).
    for (int64_t o : dag.origin)
        if (o < int64_t(std::numeric_limits<int32_t>::min()) || o > int64_t(std::numeric_limits<int32_t>::max()))
            fail("the root's origin " + std::to_string(o) + " is outside OpenVDB's int32 index range");
    // Bricks (4^3) sit on multiples of 4 from the origin, and OpenVDB's
    // leaves hold whole bricks only when the origin is a multiple of 4 too
    // (every builder aligns it so); another origin would put a brick's
    // voxels past its leaf's 512.
    for (int64_t o : dag.origin)
        if (o % 4 != 0) fail("the root's origin " + std::to_string(o) + " is not a multiple of 4 (bricks are 4^3 voxels on a 4-aligned grid)");
    const size_t levels = dag.innerLevelCount();
    if (levels != size_t(dag.log2Size) - 2) fail("level table has " + std::to_string(levels) + " levels, expected " + std::to_string(dag.log2Size - 2));
    if (dag.offsetWords.size() != levels) fail("offset width table has " + std::to_string(dag.offsetWords.size()) + " entries");
    for (uint8_t w : dag.offsetWords)
        if (w > 4) fail("attribute offsets of " + std::to_string(w) + " words are not supported (at most 4)");
    if (dag.levelStart[0] != 0) fail("root level does not start at word 0");
    // Levels below solid nodes may be empty (a grid of tiles only); the root's may not.
    for (size_t i = 0; i < levels; ++i)
        if (dag.levelStart[i] > dag.levelEnd(i) || (i == 0 && dag.levelEnd(0) == 0)) fail("inner level " + std::to_string(i) + " is out of order or the root is missing");
    for (size_t i = 0; i < dag.leaves.size(); ++i)
        if (dag.leaves[i] == 0) fail("leaf " + std::to_string(i) + " is empty");

    // Pass 1: node boundaries of every level.
    std::vector<std::vector<uint8_t>> isNodeStart(levels);
    for (size_t i = 0; i < levels; ++i) {
        const uint64_t begin = dag.levelStart[i], end = dag.levelEnd(i);
        isNodeStart[i].assign(end - begin, 0);
        uint64_t nodes = 0;
        for (uint64_t pos = begin; pos < end; ++nodes) {
            const unsigned words = nodeWordCount(dag.inner[pos], dag.offsetWords[i]);
            if (words > end - pos) fail("node at word " + std::to_string(pos) + " runs past the end of its level");
            isNodeStart[i][pos - begin] = 1;
            pos += words;
        }
        if (i == 0 && nodes != 1) fail("root level holds " + std::to_string(nodes) + " nodes, expected 1");
    }
    // Pass 2, bottom-up: every pointer lands on a node of the next level (or
    // a leaf), and every stored attribute offset is the entries of the
    // preceding siblings.
    std::vector<uint64_t> below(dag.leaves.size()), here;
    for (size_t n = 0; n < dag.leaves.size(); ++n) below[n] = uint64_t(std::popcount(dag.leaves[n]));
    for (size_t i = levels; i-- > 0;) {
        const uint64_t begin = dag.levelStart[i], end = dag.levelEnd(i);
        const bool toLeaves = i + 1 == levels;
        here.assign(end - begin, 0);
        forEachNode(dag, i, [&](uint64_t pos, uint16_t header) {
            if (header == 0) { here[pos - begin] = 1; return; }
            uint64_t preceding = 0;
            bool first = true;
            forEachStoredChild(dag, i, pos, [&](unsigned, const ChildPointer& p) {
                const bool ok = toLeaves ? p.offset < dag.leaves.size()
                                         : p.offset < isNodeStart[i + 1].size() && isNodeStart[i + 1][p.offset];
                if (!ok) fail("pointer at level " + std::to_string(i) + " word " + std::to_string(pos) + " targets " +
                              std::to_string(p.offset) + ", which is not a node of the next level");
                const uint64_t expected = atRest.empty() || !atRest[i] ? preceding : 0;  // at rest: stored as 0
                if (!first && dag.offsetWords[i] && p.attributeOffset != expected)
                    fail("attribute offset at level " + std::to_string(i) + " word " + std::to_string(pos) + " is " +
                         std::to_string(p.attributeOffset) + ", expected " + std::to_string(expected));
                first = false;
                preceding = saturatingAdd(preceding, below[p.offset]);
            });
            here[pos - begin] = preceding;
        });
        below.swap(here);
    }
}

std::vector<NodeFacts> computeFacts(const CompactDag& dag);
// The decoded size: the root's facts.
DecodedSize rootSize(const std::vector<NodeFacts>& facts) {
    const NodeFact& root = facts[0][0];
    return {root.voxels, root.bricks, root.tiles, root.entries};
}

// Calls fill(level, word, preceding) for every attribute offset of the
// levels `levels(i)` picks: its first word and the entries of the
// preceding siblings (saturating), from the DAG's `facts` (computeFacts).
template <typename Levels, typename Fill>
void forEachAttributeOffset(const CompactDag& dag, const std::vector<NodeFacts>& facts, Levels&& levels, Fill&& fill) {
    const size_t count = dag.innerLevelCount();
    for (size_t i = 0; i < count; ++i) {
        const unsigned ow = dag.offsetWords[i];
        if (ow == 0 || !levels(i)) continue;
        const bool toLeaves = i + 1 == count;
        forEachNode(dag, i, [&](uint64_t pos, uint16_t header) {
            uint64_t preceding = 0;
            bool first = true;
            forEachStoredChild(dag, i, pos, [&](unsigned j, const ChildPointer& p) {
                if (!first) fill(i, access::dagAttributeOffsetWord(pos, header, j, ow), preceding);
                first = false;
                preceding = saturatingAdd(preceding, toLeaves ? uint64_t(std::popcount(dag.leaves[p.offset])) : facts[i + 1][p.offset].entries);
            });
        });
    }
}

} // namespace

void validateCompact(const CompactDag& dag, const std::string& what) { checkCompact(dag, what, {}); }

std::vector<uint8_t> offsetWordsAtRest(const CompactDag& dag) {
    std::vector<uint8_t> out = dag.offsetWords;
    for (uint8_t& w : out)
        if (w) w |= kOffsetsAtRest;
    return out;
}

std::vector<uint16_t> innerWordsAtRest(const CompactDag& dag) {
    std::vector<uint16_t> out = dag.inner;
    if (dag.empty() || std::all_of(dag.offsetWords.begin(), dag.offsetWords.end(), [](uint8_t w) { return w == 0; })) return out;  // geometry only
    forEachAttributeOffset(
        dag, computeFacts(dag), [](size_t) { return true; },
        [&](size_t i, uint64_t word, uint64_t) { std::fill_n(out.begin() + ptrdiff_t(word), dag.offsetWords[i], uint16_t(0)); });
    return out;
}

DecodedSize validateAndRestoreOffsets(CompactDag& dag, const std::string& what) {
    std::vector<uint8_t> atRest(dag.offsetWords.size(), 0);
    bool any = false;
    for (size_t i = 0; i < dag.offsetWords.size(); ++i) {
        uint8_t& w = dag.offsetWords[i];
        if (!(w & kOffsetsAtRest)) continue;
        w &= uint8_t(~kOffsetsAtRest);
        if (w == 0) throw Error(what + ": level " + std::to_string(i) + " keeps attribute offsets at rest but stores none");
        atRest[i] = 1;
        any = true;
    }
    checkCompact(dag, what, atRest);
    if (dag.empty()) return {};
    // The facts count entries through pointers only, so they hold before
    // the offsets are filled in, and give the decoded size as well.
    const std::vector<NodeFacts> facts = computeFacts(dag);
    // Filled in place: a walk reads a node's pointers, never its offsets.
    if (any)
        forEachAttributeOffset(
            dag, facts, [&](size_t i) { return atRest[i] != 0; },
            [&](size_t i, uint64_t word, uint64_t preceding) {
                const unsigned ow = dag.offsetWords[i];
                if (ow < 4 && preceding >> (16 * ow))
                    throw Error(what + ": level " + std::to_string(i) + " needs an attribute offset of " + std::to_string(preceding) +
                                ", wider than its " + std::to_string(ow) + " words");
                for (unsigned w = 0; w < ow; ++w) dag.inner[size_t(word + w)] = uint16_t(preceding >> (16 * w));
            });
    return rootSize(facts);
}

namespace {

std::vector<NodeFacts> computeFacts(const CompactDag& dag) {
    const size_t levels = dag.innerLevelCount();
    std::vector<NodeFacts> facts(levels);
    for (size_t i = levels; i-- > 0;) {
        const uint64_t begin = dag.levelStart[i], end = dag.levelEnd(i);
        NodeFacts& level = facts[i];
        if (end - begin > std::numeric_limits<uint32_t>::max()) throw Error("a DAG level of more than 2^32 words: the grid is implausibly large");
        level.row.assign(size_t(end - begin), 0);
        size_t nodes = 0;
        forEachNode(dag, i, [&](uint64_t, uint16_t) { ++nodes; });
        level.rows.reserve(nodes);
        const unsigned log2Size = dag.log2Size - unsigned(i);
        const bool toLeaves = i + 1 == levels;
        forEachNode(dag, i, [&](uint64_t pos, uint16_t header) {
            level.row[size_t(pos - begin)] = uint32_t(level.rows.size());
            NodeFact& f = level.rows.emplace_back();
            if (header == 0) {  // solid node
                f.voxels = 3 * log2Size >= 64 ? std::numeric_limits<uint64_t>::max() : uint64_t(1) << (3 * log2Size);
                f.entries = 1;
                f.tiles = 1;
                return;
            }
            forEachStoredChild(dag, i, pos, [&](unsigned, const ChildPointer& p) {
                if (toLeaves) {
                    const uint64_t n = uint64_t(std::popcount(dag.leaves[p.offset]));
                    f.voxels += n;
                    f.entries += n;
                    f.bricks += 1;
                } else {
                    const NodeFact& c = facts[i + 1][p.offset];
                    f.voxels = saturatingAdd(f.voxels, c.voxels);
                    f.entries = saturatingAdd(f.entries, c.entries);
                    f.bricks = saturatingAdd(f.bricks, c.bricks);
                    f.tiles = saturatingAdd(f.tiles, c.tiles);
                }
            });
        });
    }
    return facts;
}

} // namespace

DecodedSize decodedSize(const CompactDag& dag) {
    if (dag.empty()) return {};
    return rootSize(computeFacts(dag));
}

uint64_t BrickInstance::spatialMask() const { return dag::reflectBrick(storedMask, mirror); }

namespace {

// The depth-first walk of DESIGN.md invariant 2 (descendFrom), counting
// attribute entries. With a cut size, nodes of that size (and solid nodes
// above it) are reported to `cut` and skipped.
struct Walker {
    const CompactDag& dag;
    const std::vector<NodeFacts>& facts;
    const BrickInstanceVisitor* brick;
    const SolidVisitor* solid;
    unsigned cutLog2 = 0;
    std::vector<SubtreeInstance>* cut = nullptr;
    uint64_t entry = 0;

    void visit(size_t level, uint64_t offset, const NodePlace& at) {
        descendFrom(
            dag, level, offset, at,
            [&](size_t i, uint64_t here, uint16_t header, const NodePlace& p) {
                const unsigned log2Size = dag.log2Size - unsigned(i);
                if (cut && (log2Size == cutLog2 || header == 0)) {
                    cut->push_back({unsigned(i), here, p.mirror, p.x, p.y, p.z, log2Size, entry, header == 0});
                    entry += facts[i][here].entries;
                    return false;
                }
                if (header == 0) (*solid)(p.x, p.y, p.z, log2Size, entry++);
                return true;
            },
            [&](uint64_t leaf, const NodePlace& p) {
                const uint64_t stored = dag.leaves[leaf];
                if (brick) (*brick)(BrickInstance{p.x, p.y, p.z, p.mirror, stored, entry});
                entry += uint64_t(std::popcount(stored));
            });
    }
};

std::vector<NodeFacts> checkedFacts(const CompactDag& dag) {
    auto facts = computeFacts(dag);
    if (saturatingAdd(facts[0][0].bricks, facts[0][0].tiles) > kMaxEmittedPieces)
        throw Error("decoding would create more than 2^31 bricks and tiles: the grid is implausibly large to decode here");
    return facts;
}

} // namespace

void visitInAttributeOrder(const CompactDag& dag, const BrickInstanceVisitor& brick, const SolidVisitor& solid) {
    if (dag.empty()) return;
    const auto facts = checkedFacts(dag);
    Walker{dag, facts, &brick, &solid}.visit(0, 0, rootPlace(dag));
}

std::vector<SubtreeInstance> subtreesInAttributeOrder(const CompactDag& dag, unsigned log2Size) {
    std::vector<SubtreeInstance> out;
    if (dag.empty()) return out;
    if (log2Size < 3 || log2Size > dag.log2Size) throw Error("internal error: subtree size out of range");
    const auto facts = computeFacts(dag);
    Walker walker{dag, facts, nullptr, nullptr, log2Size, &out};
    walker.visit(0, 0, rootPlace(dag));
    return out;
}

void visitSubtreeInAttributeOrder(const CompactDag& dag, const SubtreeInstance& root, const BrickInstanceVisitor& brick, const SolidVisitor& solid) {
    const std::vector<NodeFacts> none;  // an uncut walk reads no facts
    Walker walker{dag, none, &brick, &solid};
    walker.entry = root.firstEntry;
    walker.visit(root.level, root.offset, NodePlace{root.x, root.y, root.z, root.mirror});
}

void visitInstances(const CompactDag& dag, const BrickVisitor& brick, const TileVisitor& tile) {
    visitInAttributeOrder(
        dag, [&](const BrickInstance& b) { brick(b.x, b.y, b.z, b.spatialMask()); },
        [&](int64_t x, int64_t y, int64_t z, unsigned log2Size, uint64_t) { tile(x, y, z, log2Size); });
}

GridTopology decodeTopology(const CompactDag& dag) {
    GridTopology topology;
    topology.bricks.reserve(decodedSize(dag).emittedBricks);
    auto toInt32 = [](int64_t v) {
        if (v < std::numeric_limits<int32_t>::min() || v > std::numeric_limits<int32_t>::max())
            throw Error("decoded coordinate " + std::to_string(v) + " is outside OpenVDB's int32 index range");
        return int32_t(v);
    };
    visitInstances(
        dag, [&](int64_t x, int64_t y, int64_t z, uint64_t mask) { topology.bricks.push_back({toInt32(x), toInt32(y), toInt32(z), mask}); },
        [&](int64_t x, int64_t y, int64_t z, unsigned log2Size) {
            const int64_t size = int64_t(1) << log2Size;
            if (log2Size > 31 || (x & (size - 1)) || (y & (size - 1)) || (z & (size - 1)))
                throw Error("solid node of 2^" + std::to_string(log2Size) + " voxels at (" + std::to_string(x) + "," + std::to_string(y) + "," +
                            std::to_string(z) + ") is not aligned to its size: the file is corrupted");
            topology.tiles.push_back({toInt32(x), toInt32(y), toInt32(z), uint8_t(log2Size)});
        });
    return topology;
}

} // namespace vdbdag::encoding
