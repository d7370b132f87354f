// See ValueWindows.h: reading the windows (directory, one window, all of
// them into the traceable channel). Writing them: ValueWindowWriter.cpp.
#include "src/attributes/ValueWindows.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <memory>
#include <new>

#include "src/format/ByteIO.h"
#include "src/format/ZstdFrame.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {

std::vector<uint8_t> ValueWindowsPayload::load() const {
    if (!file) return bytes;
    std::vector<uint8_t> out;
    file->read(0, size_t(file->size()), out);
    return out;
}

WindowDirectory readValueWindowDirectory(std::span<const uint8_t> payload, const std::string& what) {
    format::ByteReader r(payload, what);
    WindowDirectory dir;
    dir.valueSize = r.get<uint32_t>();
    if (dir.valueSize == 0 || dir.valueSize > 64) r.fail("bad value size " + std::to_string(dir.valueSize));
    dir.entries = r.get<uint64_t>();
    const uint64_t windowEntries = r.get<uint64_t>();
    if (!std::has_single_bit(windowEntries) || windowEntries < (uint64_t(1) << 10) || windowEntries > (uint64_t(1) << 30))
        r.fail("window of " + std::to_string(windowEntries) + " entries (a power of two from 2^10 to 2^30 is expected)");
    const uint64_t windows = r.get<uint64_t>();
    if (dir.entries > (uint64_t(1) << 40)) r.fail(std::to_string(dir.entries) + " entries is implausible");
    if (windows != (dir.entries + windowEntries - 1) / windowEntries)
        r.fail(std::to_string(windows) + " windows for " + std::to_string(dir.entries) + " entries of " + std::to_string(windowEntries));
    if (windows > r.remaining() / 16) r.fail("window directory runs past the end");
    const size_t framesBegin = r.position(), directoryBegin = payload.size() - size_t(windows) * 16;
    format::ByteReader d(payload.subspan(directoryBegin), what + " window directory");
    uint64_t storedTotal = 0;
    const uint64_t frameBytes = directoryBegin - framesBegin;
    dir.windows.resize(size_t(windows));
    for (uint64_t w = 0; w < windows; ++w) {
        WindowDirectory::Window& e = dir.windows[size_t(w)];
        e.stored = d.get<uint64_t>();
        e.raw = d.get<uint64_t>();
        if (e.stored > frameBytes || e.raw < e.stored || !format::zstdCanProduce(e.stored, e.raw)) r.fail("window sizes are implausible");
        e.offset = framesBegin + storedTotal;
        e.firstEntry = w * windowEntries;
        e.entries = std::min(windowEntries, dir.entries - e.firstEntry);
        storedTotal += e.stored;
    }
    if (storedTotal != frameBytes) r.fail("windows hold " + std::to_string(frameBytes) + " bytes, the directory says " + std::to_string(storedTotal));
    return dir;
}

std::vector<uint8_t> windowRawBytes(std::span<const uint8_t> payload, const WindowDirectory::Window& w, const std::string& what) {
    const std::span<const uint8_t> stored = payload.subspan(size_t(w.offset), size_t(w.stored));
    if (w.raw == w.stored) return {stored.begin(), stored.end()};
    return format::zstdInflateFrame(stored, w.raw, what);
}

PaletteChannel decodeValueWindow(std::span<const uint8_t> payload, const WindowDirectory& dir, size_t k, const std::string& what) {
    const WindowDirectory::Window& w = dir.windows.at(k);
    const std::string where = what + " window " + std::to_string(k);
    PaletteChannel c = deserializePalette(windowRawBytes(payload, w, where), where);
    if (c.valueSize != dir.valueSize || c.entryCount != w.entries)
        throw Error(where + ": holds " + std::to_string(c.entryCount) + " entries of " + std::to_string(c.valueSize) + " bytes, expected " +
                    std::to_string(w.entries) + " of " + std::to_string(dir.valueSize));
    return c;
}

PaletteChannel decodeValueWindows(std::span<const uint8_t> payload, const std::string& what) {
    const WindowDirectory dir = readValueWindowDirectory(payload, what);
    PaletteChannel out;
    out.valueSize = dir.valueSize;
    out.entryCount = dir.entries;
    for (size_t w = 0; w < dir.windows.size(); ++w) {
        const std::string where = what + " window " + std::to_string(w);
        const PaletteChannel c = decodeValueWindow(payload, dir, w, what);
        const uint64_t first = dir.windows[w].firstEntry;
        // Merge: materials and palettes appended (palette entries moved by
        // the material base), blocks moved to the merged arrays.
        const uint64_t materialBase = out.materialCount(), paletteBase = out.palettes.size();
        const uint64_t bitBase = uint64_t(out.indexBits.size()) * 64, directBase = out.direct.size();
        if (materialBase + c.materialCount() > 0xFFFFFFF0u || paletteBase + c.palettes.size() + c.materialCount() > 0xFFFFFFF0u)
            throw Error(where + ": more than 2^32 materials or palette entries in one channel");
        out.materials.insert(out.materials.end(), c.materials.begin(), c.materials.end());
        for (uint32_t m : c.palettes) out.palettes.push_back(uint32_t(materialBase + m));
        uint32_t wholeOffset = PaletteBlock::kWholeMaterialArray;
        for (PaletteBlock b : c.blocks) {
            b.firstEntry += first;
            if (b.indexBits == PaletteBlock::kDirect) {
                b.dataOffset += directBase;
            } else {
                b.dataOffset += bitBase;
                if (b.paletteOffset == PaletteBlock::kWholeMaterialArray) {
                    if (wholeOffset == PaletteBlock::kWholeMaterialArray) {  // this window's materials as one palette
                        wholeOffset = uint32_t(out.palettes.size());
                        for (uint64_t m = 0; m < c.materialCount(); ++m) out.palettes.push_back(uint32_t(materialBase + m));
                    }
                    b.paletteOffset = wholeOffset;
                } else {
                    b.paletteOffset = uint32_t(paletteBase + b.paletteOffset);
                }
            }
            out.blocks.push_back(b);
        }
        out.indexBits.insert(out.indexBits.end(), c.indexBits.begin(), c.indexBits.end());
        out.direct.insert(out.direct.end(), c.direct.begin(), c.direct.end());
    }
    if (out.indexBits.empty() && !out.blocks.empty()) out.indexBits.assign(2, 0);
    return out;
}

} // namespace vdbdag::attributes
