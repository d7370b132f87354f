// The traceable layout of a palette channel (PaletteChannel.h): random
// access to an entry, the whole channel in order, and the serialisation of
// the Values sections. The compressor that builds it is PaletteCompressor.cpp.
#include "src/attributes/PaletteChannel.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include "src/format/ByteIO.h"
#include "src/util/Error.h"

// The lookup itself is the one source shared with the shaders
// (include/vdbdag/palette_access.h), reading this channel's vectors.
#define VDBDAG_PALETTE_T const vdbdag::attributes::PaletteChannel&
#define VDBDAG_PALETTE_BLOCK_COUNT(c) uint64_t((c).blocks.size())
#define VDBDAG_PALETTE_BLOCK_FIRST(c, b) (c).blocks[b].firstEntry
#define VDBDAG_PALETTE_BLOCK_DATA(c, b) (c).blocks[b].dataOffset
#define VDBDAG_PALETTE_BLOCK_PALETTE(c, b) uint((c).blocks[b].paletteOffset)
#define VDBDAG_PALETTE_BLOCK_BITS(c, b) uint((c).blocks[b].indexBits)
#define VDBDAG_PALETTE_INDEX_WORD(c, w) (c).indexBits[w]
#define VDBDAG_PALETTE_ENTRY(c, i) uint((c).palettes[i])
#define VDBDAG_PALETTE_VALUE_SIZE(c) uint((c).valueSize)
#include <vdbdag/palette_access.h>

static_assert(vdbdag::attributes::PaletteBlock::kDirect == vdbdag::access::kPaletteDirect);
static_assert(vdbdag::attributes::PaletteBlock::kWholeMaterialArray == vdbdag::access::kPaletteWholeMaterialArray);

namespace vdbdag::attributes {

uint64_t readPackedBits(const PaletteChannel& channel, uint64_t bitOffset, unsigned bits) { return access::paletteBits(channel, bitOffset, bits); }

uint64_t PaletteChannel::byteSize() const {
    return materials.size() + palettes.size() * 4 + blocks.size() * sizeof(PaletteBlock) + indexBits.size() * 8 + direct.size();
}

void PaletteChannel::lookup(uint64_t index, uint8_t* out) const {
    size_t hint = 0;
    lookup(index, out, hint);
}

void PaletteChannel::lookup(uint64_t index, uint8_t* out, size_t& hint) const {
    uint64_t block = hint;
    bool isDirect = false;
    const uint64_t at = access::paletteLocate(*this, index, block, isDirect);
    hint = size_t(block);
    std::memcpy(out, isDirect ? &direct[at] : &materials[at], valueSize);
}

std::vector<uint8_t> PaletteChannel::decodeAll() const {
    std::vector<uint8_t> out(entryCount * valueSize);
    for (size_t bi = 0; bi < blocks.size(); ++bi) {
        const PaletteBlock& b = blocks[bi];
        const uint64_t end = bi + 1 < blocks.size() ? blocks[bi + 1].firstEntry : entryCount;
        if (b.indexBits == PaletteBlock::kDirect) {
            std::memcpy(&out[b.firstEntry * valueSize], &direct[b.dataOffset], (end - b.firstEntry) * valueSize);
            continue;
        }
        size_t hint = bi;
        for (uint64_t e = b.firstEntry; e < end; ++e) lookup(e, &out[e * valueSize], hint);
    }
    return out;
}

namespace {

// Byte planes (all values' byte 0, then byte 1, ...): zstd compresses the
// planes of floats much better than interleaved bytes.
std::vector<uint8_t> shuffle(const std::vector<uint8_t>& v, uint32_t vs) {
    const size_t n = vs ? v.size() / vs : 0;
    std::vector<uint8_t> out(v.size());
    for (size_t i = 0; i < n; ++i)
        for (uint32_t k = 0; k < vs; ++k) out[k * n + i] = v[i * vs + k];
    return out;
}
std::vector<uint8_t> unshuffle(const std::vector<uint8_t>& p, uint32_t vs) {
    const size_t n = vs ? p.size() / vs : 0;
    std::vector<uint8_t> out(p.size());
    for (size_t i = 0; i < n; ++i)
        for (uint32_t k = 0; k < vs; ++k) out[i * vs + k] = p[k * n + i];
    return out;
}

// Differences of consecutive little-endian unsigned values of `vs` bytes
// (vs = 1, 2, 4 or 8; modulo 2^(8 vs)), in place, and back. Other sizes
// are left as they are.
bool deltaCodable(uint32_t vs) { return vs == 1 || vs == 2 || vs == 4 || vs == 8; }
uint64_t loadUnsigned(const uint8_t* p, uint32_t vs) {
    uint64_t v = 0;
    std::memcpy(&v, p, vs);
    return v;
}
void storeUnsigned(uint8_t* p, uint64_t v, uint32_t vs) { std::memcpy(p, &v, vs); }
std::vector<uint8_t> toDifferences(std::vector<uint8_t> v, uint32_t vs) {
    if (!deltaCodable(vs)) return v;
    uint64_t previous = 0;
    for (size_t at = 0; at + vs <= v.size(); at += vs) {
        const uint64_t x = loadUnsigned(&v[at], vs);
        storeUnsigned(&v[at], x - previous, vs);
        previous = x;
    }
    return v;
}
std::vector<uint8_t> fromDifferences(std::vector<uint8_t> v, uint32_t vs) {
    if (!deltaCodable(vs)) return v;
    uint64_t sum = 0;
    for (size_t at = 0; at + vs <= v.size(); at += vs) {
        sum += loadUnsigned(&v[at], vs);
        storeUnsigned(&v[at], sum, vs);
    }
    return v;
}
std::vector<uint8_t> bytesOf(const std::vector<uint32_t>& v) {
    std::vector<uint8_t> out(v.size() * 4);
    if (!v.empty()) std::memcpy(out.data(), v.data(), out.size());
    return out;
}

// The first u32 of a serialised channel: the value size (1..64), with this
// bit set in the layout below (files before it hold the value size alone).
constexpr uint32_t kColumnLayout = 0x80000000u;

} // namespace

// Layout (FORMAT.md §7): u32 valueSize | kColumnLayout, u64 entries,
// u64 materials bytes + bytes (sorted; differences, then byte planes),
// u64 palette count + u32[] (differences, byte planes),
// u64 blocks + the directory by columns: u64 first entries (differences),
// u64 data offsets, u32 palette offsets, u8 ω,
// u64 index words + u64[], u64 direct bytes + bytes (byte planes).
// The older layout (no kColumnLayout bit) held the materials and direct
// values in byte planes, the palettes as they are and the directory by rows.
std::vector<uint8_t> serializePalette(const PaletteChannel& c) {
    format::ByteWriter w;
    w.put<uint32_t>(c.valueSize | kColumnLayout);
    w.put<uint64_t>(c.entryCount);
    w.put<uint64_t>(c.materials.size());
    w.putBytes(shuffle(toDifferences(c.materials, c.valueSize), c.valueSize));
    w.put<uint64_t>(c.palettes.size());
    w.putBytes(shuffle(toDifferences(bytesOf(c.palettes), 4), 4));
    w.put<uint64_t>(c.blocks.size());
    uint64_t previous = 0;
    for (const PaletteBlock& b : c.blocks) {
        w.put<uint64_t>(b.firstEntry - previous);
        previous = b.firstEntry;
    }
    for (const PaletteBlock& b : c.blocks) w.put<uint64_t>(b.dataOffset);
    for (const PaletteBlock& b : c.blocks) w.put<uint32_t>(b.paletteOffset);
    for (const PaletteBlock& b : c.blocks) w.put<uint8_t>(b.indexBits);
    w.put<uint64_t>(c.indexBits.size());
    w.putArray<uint64_t>(c.indexBits);
    w.put<uint64_t>(c.direct.size());
    w.putBytes(shuffle(c.direct, c.valueSize));
    return w.take();
}

PaletteChannel deserializePalette(std::span<const uint8_t> bytes, const std::string& what) {
    format::ByteReader r(bytes, what);
    PaletteChannel c;
    const uint32_t head = r.get<uint32_t>();
    const bool columns = (head & kColumnLayout) != 0;
    c.valueSize = head & ~kColumnLayout;
    if (c.valueSize == 0 || c.valueSize > 64) r.fail("bad value size");
    c.entryCount = r.get<uint64_t>();
    const uint64_t materialBytes = r.get<uint64_t>();
    if (materialBytes % c.valueSize) r.fail("material array is not a whole number of values");
    c.materials = unshuffle(r.getArray<uint8_t>(materialBytes), c.valueSize);
    if (columns) c.materials = fromDifferences(std::move(c.materials), c.valueSize);
    const uint64_t paletteCount = r.get<uint64_t>();
    if (columns) {
        if (paletteCount > r.remaining() / 4) r.fail("palettes run past the end");
        const std::vector<uint8_t> planes = fromDifferences(unshuffle(r.getArray<uint8_t>(paletteCount * 4), 4), 4);
        c.palettes.resize(paletteCount);
        if (paletteCount) std::memcpy(c.palettes.data(), planes.data(), planes.size());
    } else {
        c.palettes = r.getArray<uint32_t>(paletteCount);
    }
    const uint64_t blockCount = r.get<uint64_t>();
    if (blockCount > r.remaining() / 21) r.fail("block directory runs past the end");
    c.blocks.resize(blockCount);
    if (columns) {
        uint64_t sum = 0;
        for (PaletteBlock& b : c.blocks) {
            const uint64_t step = r.get<uint64_t>();
            if (step > c.entryCount - std::min(sum, c.entryCount)) r.fail("block directory runs past the entries");
            b.firstEntry = sum += step;
        }
        for (PaletteBlock& b : c.blocks) b.dataOffset = r.get<uint64_t>();
        for (PaletteBlock& b : c.blocks) b.paletteOffset = r.get<uint32_t>();
        for (PaletteBlock& b : c.blocks) b.indexBits = r.get<uint8_t>();
    } else {
        for (PaletteBlock& b : c.blocks) {
            b.firstEntry = r.get<uint64_t>();
            b.dataOffset = r.get<uint64_t>();
            b.paletteOffset = r.get<uint32_t>();
            b.indexBits = r.get<uint8_t>();
        }
    }
    c.indexBits = r.getArray<uint64_t>(r.get<uint64_t>());
    const uint64_t directBytes = r.get<uint64_t>();
    if (directBytes % c.valueSize) r.fail("direct values are not a whole number of values");
    c.direct = unshuffle(r.getArray<uint8_t>(directBytes), c.valueSize);
    r.expectEnd();
    // Every block must be addressable: entries in order, data in range.
    const uint64_t materialsCount = c.materialCount();
    for (size_t i = 0; i < c.blocks.size(); ++i) {
        const PaletteBlock& b = c.blocks[i];
        const uint64_t end = i + 1 < c.blocks.size() ? c.blocks[i + 1].firstEntry : c.entryCount;
        if ((i == 0 && b.firstEntry != 0) || b.firstEntry >= end) r.fail("block " + std::to_string(i) + " is out of order");
        const uint64_t len = end - b.firstEntry;
        if (b.indexBits == PaletteBlock::kDirect) {
            if (b.dataOffset > c.direct.size() || len > (c.direct.size() - b.dataOffset) / c.valueSize) r.fail("direct block " + std::to_string(i) + " out of range");
            continue;
        }
        const bool whole = b.paletteOffset == PaletteBlock::kWholeMaterialArray;
        if (b.indexBits > (whole ? 32 : 8)) r.fail("block " + std::to_string(i) + " has " + std::to_string(b.indexBits) + "-bit indices");
        if (!whole && b.paletteOffset > c.palettes.size()) r.fail("palette of block " + std::to_string(i) + " out of range");
        const uint64_t available = whole ? materialsCount : std::min<uint64_t>(uint64_t(1) << b.indexBits, c.palettes.size() - b.paletteOffset);
        // readPackedBits may read one word past a block's last bit: the writer keeps a spare word.
        if (c.indexBits.empty() || len > (uint64_t(1) << 40) || b.dataOffset > (uint64_t(1) << 62) ||
            b.dataOffset + len * b.indexBits > (c.indexBits.size() - 1) * 64)
            r.fail("indices of block " + std::to_string(i) + " out of range");
        // Every index must land in the palette and every palette entry in M
        // (0-bit indices are all 0: one check, not one per entry, so a
        // 21-byte block cannot cost 2^40 steps).
        if (b.indexBits == 0) {
            if (available == 0) r.fail("index out of its palette in block " + std::to_string(i));
            continue;
        }
        for (uint64_t k = 0; k < len; ++k) {
            const uint64_t local = readPackedBits(c, b.dataOffset + k * b.indexBits, b.indexBits);
            if (local >= available) r.fail("index out of its palette in block " + std::to_string(i));
        }
    }
    for (size_t i = 0; i < c.palettes.size(); ++i)
        if (c.palettes[i] >= materialsCount) r.fail("palette entry " + std::to_string(i) + " is not a material");
    if (c.blocks.empty() && c.entryCount) r.fail("no blocks for " + std::to_string(c.entryCount) + " entries");
    return c;
}


} // namespace vdbdag::attributes
