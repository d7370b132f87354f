// A palette-compressed attribute channel (Dado et al. §4.2): a global
// material array M of the distinct values used through palettes, a block
// directory (sorted by first entry, found by binary search), per block
// either an ω-bit index (ω = 0..8) into a shared palette of material
// indices, or - when palettes do not pay, e.g. unique floats - the values
// stored directly. Random access in O(log blocks); this is the traceable
// in-memory layout.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace vdbdag::attributes {

struct PaletteBlock {
    uint64_t firstEntry;     // attribute index of the block's first entry
    uint64_t dataOffset;     // direct: byte offset into `direct`; palette: bit offset into `indexBits`
    uint32_t paletteOffset;  // first material index of the block's palette in `palettes`
    uint8_t indexBits;       // ω; kDirect for direct storage
    static constexpr uint8_t kDirect = 0xFF;
    // paletteOffset of a block whose indices address the material array
    // directly (the "material + index" scheme, for blocks too varied for a
    // 2^8-entry palette); its indexBits is ceil(log2 λ).
    static constexpr uint32_t kWholeMaterialArray = 0xFFFFFFFFu;
};

struct PaletteChannel {
    uint32_t valueSize = 0;
    uint64_t entryCount = 0;                  // Λ
    std::vector<uint8_t> materials;           // M: distinct values (valueSize bytes each)
    std::vector<uint32_t> palettes;           // all palettes, concatenated (material indices)
    std::vector<PaletteBlock> blocks;         // directory, by firstEntry
    std::vector<uint64_t> indexBits;          // bit-packed palette indices of all palette blocks
    std::vector<uint8_t> direct;              // values of direct blocks

    uint64_t materialCount() const { return valueSize ? materials.size() / valueSize : 0; }
    // Bytes of the traceable layout (what a tracer binds).
    uint64_t byteSize() const;
    // Copies entry `index`'s value (valueSize bytes) to `out`.
    void lookup(uint64_t index, uint8_t* out) const;
    // The same, trying block `hint` first and leaving the block used in it:
    // a walk that reads nearby entries skips most binary searches.
    void lookup(uint64_t index, uint8_t* out, size_t& hint) const;
    // All entries, in order (for decoding).
    std::vector<uint8_t> decodeAll() const;
};

// The `bits`-bit field (0..63 bits) at `bitOffset` of the channel's
// bit-packed indices (PaletteChannel::indexBits).
uint64_t readPackedBits(const PaletteChannel& channel, uint64_t bitOffset, unsigned bits);

// Serialisation for the .ssvdag Values sections (validated on read).
std::vector<uint8_t> serializePalette(const PaletteChannel& channel);
PaletteChannel deserializePalette(std::span<const uint8_t> bytes, const std::string& what);

// compressPalette, which builds a channel: PaletteCompressor.h.

} // namespace vdbdag::attributes
