// Inside bits of a level set's values; see InsideBits.h.
#include "src/trace/InsideBits.h"

#include <cstring>

namespace vdbdag::trace {
namespace {

bool insideValue(const uint8_t* bytes, ValueType type) {
    if (type == ValueType::Double) {
        double d;
        std::memcpy(&d, bytes, 8);
        return d <= 0;
    }
    float f;
    std::memcpy(&f, bytes, 4);
    return f <= 0;
}

} // namespace

InsideBits insideBitsOf(const attributes::PaletteChannel& values, ValueType type) {
    InsideBits out;
    out.entryCount = values.entryCount;
    out.words.assign((values.entryCount + 63) / 64, 0);
    const unsigned vs = values.valueSize;
    // Each material's bit once; blocks then only gather.
    std::vector<uint8_t> materialInside(values.materialCount());
    for (size_t m = 0; m < materialInside.size(); ++m) materialInside[m] = insideValue(&values.materials[m * vs], type);
    auto set = [&](uint64_t e) { out.words[e >> 6] |= uint64_t(1) << (e & 63); };
    for (size_t bi = 0; bi < values.blocks.size(); ++bi) {
        const attributes::PaletteBlock& b = values.blocks[bi];
        const uint64_t end = bi + 1 < values.blocks.size() ? values.blocks[bi + 1].firstEntry : values.entryCount;
        if (b.indexBits == attributes::PaletteBlock::kDirect) {
            for (uint64_t e = b.firstEntry; e < end; ++e)
                if (insideValue(&values.direct[b.dataOffset + (e - b.firstEntry) * vs], type)) set(e);
            continue;
        }
        const bool whole = b.paletteOffset == attributes::PaletteBlock::kWholeMaterialArray;
        for (uint64_t e = b.firstEntry; e < end; ++e) {
            const uint64_t local = attributes::readPackedBits(values, b.dataOffset + (e - b.firstEntry) * b.indexBits, b.indexBits);
            const uint64_t m = whole ? local : values.palettes[b.paletteOffset + local];
            if (materialInside[m]) set(e);
        }
    }
    return out;
}

} // namespace vdbdag::trace
