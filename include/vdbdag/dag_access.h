// The compact DAG's words read once, for C++ and GLSL alike (the PNanoVDB
// approach: one source, compiled as either language). Everything that
// decodes the inner words and 4^3 leaves of a .ssvdag DAG (docs/FORMAT.md
// §5) lives here: child tags, tagged pointers with their reflection and
// attribute offset, a node's word count, the stored bit of a voxel in a
// mirrored leaf and its popcount rank, the two steps of a point lookup
// (dagDescend, dagLeafEntry), and the reflection of a leaf mask;
// and what writes the pointers (dagPointerTag, dagPointerWord0/1). The
// public reader (src/reader/Accessor.cpp), the writer and its checks
// (src/encoding/CompactDag.cpp), the CPU tracer (src/trace/DagWalk.h) and
// the Vulkan shaders (gpu/shaders/trace_walk.glsl) all include it.
//
// C++: include it as is; the functions are in namespace vdbdag::access and
// read inner words from a `const uint16_t*`.
// GLSL: #define VDBDAG_GLSL and VDBDAG_INNER_WORD(buf, index) (a uint read
// of 16-bit word `index`; `buf` is whatever the shader passes through, e.g.
// a dummy 0u when the words are a global) before including it, with
// GL_EXT_shader_explicit_arithmetic_types_int64 enabled.
//
// Words (FORMAT.md §5): a node is a 16-bit header of eight 2-bit child tags
// (00 no child, 01 a one-word pointer, 1x a two-word pointer; a header of 0 is
// a solid node), then per stored child in slot order its pointer words (the
// top 3 bits of the first word: the child's reflection; the offset: 13 bits,
// or 30 with the tag's low bit as bit 29) and, for every child but the first,
// `offsetWords` words of attribute offset (little-endian 16-bit pieces).
#ifndef VDBDAG_DAG_ACCESS_H
#define VDBDAG_DAG_ACCESS_H

#include "shader_lang.h"

#ifdef VDBDAG_GLSL
#define VDBDAG_INNER_BUF uint
#else
#define VDBDAG_INNER_BUF const uint16_t*
#define VDBDAG_INNER_WORD(buf, index) uint((buf)[index])
#endif

VDBDAG_NAMESPACE_BEGIN

// The 2-bit tag of stored child slot j (0: none).
VDBDAG_PURE uint dagChildTag(uint header, uint j) { return (header >> (2u * j)) & 3u; }

// The pointer of stored child slot j (tag != 0) of the node whose nonzero
// header is at word `pos`: the child's offset in words of the next level
// (16-bit inner words, or 64-bit leaf masks below the last inner level), its
// reflection, and its attribute offset (entries of the stored siblings
// before it; 0 for the first, and without offsets).
VDBDAG_FN void dagChildPointer(VDBDAG_INNER_BUF buf, uint64_t pos, uint header, uint j, uint offsetWords, VDBDAG_OUT(uint64_t) offset,
                               VDBDAG_OUT(uint) reflection, VDBDAG_OUT(uint64_t) attributeOffset) {
    // Tags of the slots before j: 00 none, 01 one word, 1x two words.
    const uint earlier = header & ((1u << (2u * j)) - 1u);
    const uint before = uint(bitCount((earlier | (earlier >> 1u)) & 0x5555u));
    uint64_t at = pos + 1ul + uint64_t(before) + uint64_t(bitCount((earlier >> 1u) & 0x5555u));
    if (before > 1u) at += uint64_t(before - 1u) * uint64_t(offsetWords);
    const uint tag = dagChildTag(header, j);
    const uint w0 = VDBDAG_INNER_WORD(buf, at);
    reflection = w0 >> 13u;
    if (tag == 1u) {
        offset = uint64_t(w0 & 0x1FFFu);
        at += 1ul;
    } else {
        offset = (uint64_t(tag & 1u) << 29u) | (uint64_t(w0 & 0x1FFFu) << 16u) | uint64_t(VDBDAG_INNER_WORD(buf, at + 1ul));
        at += 2ul;
    }
    attributeOffset = 0ul;
    if (before > 0u) {
        switch (offsetWords) {  // constant per level: predicted, unlike a loop's exit
        case 0u: break;
        case 1u: attributeOffset = uint64_t(VDBDAG_INNER_WORD(buf, at)); break;
        case 2u: attributeOffset = uint64_t(VDBDAG_INNER_WORD(buf, at)) | (uint64_t(VDBDAG_INNER_WORD(buf, at + 1ul)) << 16u); break;
        default:
            for (uint w = 0u; w < offsetWords; ++w) attributeOffset |= uint64_t(VDBDAG_INNER_WORD(buf, at + uint64_t(w))) << (16u * w);
        }
    }
}

// The word where stored child slot j's attribute offset begins, in the node
// whose nonzero header is at word `pos` (j must not be its first stored
// child): where a reader fills in the offsets a file keeps at rest as 0
// (FORMAT.md 6.2).
VDBDAG_PURE uint64_t dagAttributeOffsetWord(uint64_t pos, uint header, uint j, uint offsetWords) {
    const uint through = header & ((1u << (2u * j + 2u)) - 1u);  // slots 0..j
    const uint present = uint(bitCount((through | (through >> 1u)) & 0x5555u));
    return pos + 1ul + uint64_t(present) + uint64_t(bitCount((through >> 1u) & 0x5555u)) + uint64_t(present - 2u) * uint64_t(offsetWords);
}

// One step of a point lookup, the walk every reader of a voxel takes (the
// public reader's Accessor, DagTracer::find, the shaders' findVoxel): in the
// node whose nonzero header is at word `pos`, the child whose cube holds the
// voxel (x, y, z) (relative to the root's corner; children of size
// 2^childLog2).
// False where that child is empty. Else its offset (in the next level's
// words, or among the leaf masks below the last inner level), and `mirror`
// and `base` (the entry of the cube's first stored voxel) become the child's.
VDBDAG_FN bool dagDescend(VDBDAG_INNER_BUF buf, uint64_t pos, uint header, uint64_t x, uint64_t y, uint64_t z, uint childLog2, uint offsetWords,
                          VDBDAG_INOUT(uint) mirror, VDBDAG_INOUT(uint64_t) base, VDBDAG_OUT(uint64_t) offset) {
    const uint spatial = uint((x >> childLog2) & 1ul) | (uint((y >> childLog2) & 1ul) << 1u) | (uint((z >> childLog2) & 1ul) << 2u);
    const uint slot = spatial ^ mirror;
    offset = 0ul;
    if (dagChildTag(header, slot) == 0u) return false;
    uint reflection;
    uint64_t attributeOffset;
    dagChildPointer(buf, pos, header, slot, offsetWords, offset, reflection, attributeOffset);
    mirror ^= reflection;
    base += attributeOffset;
    return true;
}

// Words of the node whose header is `header` (nonzero: a solid node is its
// header alone): the header, each stored child's pointer (one word for
// tag 01, two for 1x) and, for every child but the first, `offsetWords`
// words of attribute offset.
VDBDAG_PURE uint dagNodeWords(uint header, uint offsetWords) {
    const uint tags = header & 0xFFFFu;
    const uint children = uint(bitCount((tags | (tags >> 1u)) & 0x5555u));
    const uint longPointers = uint(bitCount((tags >> 1u) & 0x5555u));
    return 1u + children + longPointers + (children > 1u ? (children - 1u) * offsetWords : 0u);
}

// The writer's side of dagChildPointer. The tag of a pointer to a child at
// word `offset` of the next level: 1 (one word) below 2^13 where one-word
// pointers are allowed, else 2 or 3 (two words; the tag's low bit is
// offset bit 29) below 2^30, else 0 (no pointer can reach it).
VDBDAG_PURE uint dagPointerTag(uint64_t offset, bool oneWord) {
    if (oneWord && offset < 8192ul) return 1u;
    if (offset < 1073741824ul) return 2u | uint(offset >> 29u);
    return 0u;
}
// The pointer's first word (the reflection in its top 3 bits, then the
// offset, or bits 16-28 of it) and, for tags 2 and 3, its second (bits 0-15).
VDBDAG_PURE uint dagPointerWord0(uint64_t offset, uint reflection, uint tag) {
    return (reflection << 13u) | uint((tag == 1u ? offset : offset >> 16u) & 0x1FFFul);
}
VDBDAG_PURE uint dagPointerWord1(uint64_t offset) { return uint(offset & 0xFFFFul); }

// Bit of a 4^3 leaf stored under reflection m for spatial voxel (x, y, z),
// each in 0..3: bit x + 4y + 16z of the stored mask after mirroring.
VDBDAG_PURE uint dagStoredBit(uint x, uint y, uint z, uint m) {
    if ((m & 1u) != 0u) x = 3u - x;
    if ((m & 2u) != 0u) y = 3u - y;
    if ((m & 4u) != 0u) z = 3u - z;
    return x + 4u * y + 16u * z;
}

// Set bits of a 64-bit mask.
VDBDAG_PURE uint dagPopcount64(uint64_t x) {
    return uint(bitCount(uint(x & 0xFFFFFFFFul))) + uint(bitCount(uint(x >> 32u)));
}

// The entry rank of stored bit `bit` among the leaf's set bits below it.
VDBDAG_PURE uint dagLeafRank(uint64_t mask, uint bit) { return dagPopcount64(mask & ((uint64_t(1) << bit) - 1ul)); }

// The last step of a point lookup: the voxel (x, y, z) (its low two bits)
// of the 4^3 leaf `mask` stored under `mirror`, whose first entry is `base`.
// False where the voxel is not stored (inactive); else its entry.
VDBDAG_FN bool dagLeafEntry(uint64_t mask, uint64_t x, uint64_t y, uint64_t z, uint mirror, uint64_t base, VDBDAG_OUT(uint64_t) entry) {
    const uint bit = dagStoredBit(uint(x & 3ul), uint(y & 3ul), uint(z & 3ul), mirror);
    entry = base + uint64_t(dagLeafRank(mask, bit));
    return ((mask >> bit) & 1ul) != 0ul;
}

// A 4^3 leaf mask reflected by m (x: reverse every row's 4 bits; y: the 4
// rows of every 16-bit slice; z: the 4 slices).
VDBDAG_PURE uint64_t dagReflectBrick(uint64_t mask, uint m) {
    if ((m & 1u) != 0u) {
        mask = ((mask & 0x3333333333333333ul) << 2u) | ((mask >> 2u) & 0x3333333333333333ul);
        mask = ((mask & 0x5555555555555555ul) << 1u) | ((mask >> 1u) & 0x5555555555555555ul);
    }
    if ((m & 2u) != 0u) {
        mask = ((mask & 0x00FF00FF00FF00FFul) << 8u) | ((mask >> 8u) & 0x00FF00FF00FF00FFul);
        mask = ((mask & 0x0F0F0F0F0F0F0F0Ful) << 4u) | ((mask >> 4u) & 0x0F0F0F0F0F0F0F0Ful);
    }
    if ((m & 4u) != 0u) {
        mask = (mask << 32u) | (mask >> 32u);
        mask = ((mask & 0x0000FFFF0000FFFFul) << 16u) | ((mask >> 16u) & 0x0000FFFF0000FFFFul);
    }
    return mask;
}

VDBDAG_NAMESPACE_END

#ifndef VDBDAG_GLSL
#undef VDBDAG_INNER_WORD
#endif
#undef VDBDAG_INNER_BUF
#endif
