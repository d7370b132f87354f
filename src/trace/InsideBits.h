// One bit per attribute entry of a level set: whether its value is <= 0
// (inside the surface; NaN is not). A render-time cache derived from the
// palette-compressed values (Dado et al. §4.2) so that the zero-crossing
// walk through a narrow band tests a bit per voxel instead of decoding a
// palette entry; it costs Λ/8 bytes (0.45 MB for the 3.63M-entry
// bunny) next to the traceable encoding, and is built once per render.
#pragma once
#include <cstdint>
#include <vector>

#include "src/attributes/PaletteChannel.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::trace {

struct InsideBits {
    std::vector<uint64_t> words;
    uint64_t entryCount = 0;
    bool inside(uint64_t entry) const { return entry < entryCount && ((words[entry >> 6] >> (entry & 63)) & 1u); }
    // Whether any of the `count` (<= 64) entries from `first` is inside.
    bool anyInside(uint64_t first, unsigned count) const {
        if (count == 0 || first >= entryCount) return false;
        const uint64_t word = first >> 6;
        const unsigned shift = unsigned(first & 63);
        uint64_t bits = words[word] >> shift;
        if (shift + count > 64 && word + 1 < words.size()) bits |= words[word + 1] << (64 - shift);
        return (count == 64 ? bits : bits & ((uint64_t(1) << count) - 1)) != 0;
    }
};

// `type` must be Float or Double.
InsideBits insideBitsOf(const attributes::PaletteChannel& values, ValueType type);

} // namespace vdbdag::trace
