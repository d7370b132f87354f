// See PredictedWindows.h: reading the windows (directory, one window, all
// of them). Writing them: PredictedWindowWriter.cpp.
#include "src/attributes/PredictedWindows.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <exception>
#include <iterator>

#include "src/attributes/ContextChannel.h"
#include "src/attributes/PredictedChannel.h"
#include "src/attributes/RescaledFloats.h"
#include "src/coding/FloatIntegerCoder.h"
#include "src/coding/FloatValueCoder.h"
#include "src/format/ByteIO.h"
#include "src/format/ZstdFrame.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {

std::vector<uint64_t> predictedWindowCodings(std::span<const uint8_t> payload, uint32_t valueSize, std::span<const uint64_t> layout,
                                             const std::string& what) {
    const WindowDirectory dir = readPredictedWindowDirectory(payload, valueSize, layout, what);
    std::vector<uint64_t> counts(static_cast<size_t>(detail::kCodingCount));
    for (size_t k = 0; k < dir.windows.size(); ++k) {
        const WindowDirectory::Window& e = dir.windows[k];
        const std::span<const uint8_t> stored = payload.subspan(size_t(e.offset), size_t(e.stored));
        const std::vector<uint8_t> first = e.stored == e.raw ? std::vector<uint8_t>(stored.begin(), stored.begin() + 1)
                                                             : format::zstdFirstBytes(stored, 1, what + " window " + std::to_string(k));
        if (first.empty() || first[0] >= counts.size()) throw Error(what + " window " + std::to_string(k) + ": unknown coding");
        ++counts[first[0]];
    }
    return counts;
}

std::vector<uint64_t> predictedWindowCodings(uint64_t payloadBytes, const PayloadPart& read, uint32_t valueSize, const std::string& what) {
    constexpr uint64_t kHead = 4 + 8 + 8 + 8;
    if (payloadBytes < kHead) throw Error(what + ": truncated");
    const std::vector<uint8_t> head = read(0, kHead);
    format::ByteReader r(head, what);
    if (const uint32_t vs = r.get<uint32_t>(); vs != valueSize) r.fail("holds " + std::to_string(vs) + "-byte values, expected " + std::to_string(valueSize));
    r.get<uint64_t>();  // entries
    r.get<uint64_t>();  // entries per window
    const uint64_t windows = r.get<uint64_t>();
    if (windows > (payloadBytes - kHead) / detail::kPredictedDirectoryEntryBytes) r.fail("window directory runs past the end");
    const uint64_t directoryBegin = payloadBytes - windows * detail::kPredictedDirectoryEntryBytes;
    const std::vector<uint8_t> directory = read(directoryBegin, windows * detail::kPredictedDirectoryEntryBytes);
    format::ByteReader d(directory, what + " window directory");
    std::vector<uint64_t> counts(static_cast<size_t>(detail::kCodingCount));
    uint64_t at = kHead;
    for (uint64_t k = 0; k < windows; ++k) {
        const uint64_t stored = d.get<uint64_t>(), raw = d.get<uint64_t>();
        d.get<uint64_t>();  // entries
        if (stored == 0 || stored > directoryBegin - at || raw < stored || !format::zstdCanProduce(stored, raw)) r.fail("window sizes are implausible");
        const std::string window = what + " window " + std::to_string(k);
        const std::vector<uint8_t> first = stored == raw ? read(at, 1) : format::zstdFirstBytes(read(at, stored), 1, window);
        if (first.empty() || first[0] >= counts.size()) throw Error(window + ": unknown coding");
        ++counts[first[0]];
        at += stored;
    }
    return counts;
}

const char* predictedCodingName(uint8_t coding) {
    static const char* const names[] = {"palettes", "brick residuals", "context-coded", "placed context-coded", "placed labels",
                                        "rescaled floats", "context-coded", "labels", "predicted floats", "predicted vectors",
                                        "fitted context-coded", "fitted rescaled floats", "float integers", "wide fitted context-coded",
                                        "wide fitted rescaled floats", "banded context-coded", "banded rescaled floats", "shaped labels", "tiled labels",
                                        "tiled banded context-coded", "tiled banded rescaled floats", "referenced context-coded",
                                        "referenced rescaled floats"};
    static_assert(std::size(names) == detail::kCodingCount);
    return coding < std::size(names) ? names[coding] : "unknown";
}

std::vector<uint8_t> encodeFloatVectors(std::span<const uint8_t> values, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places) {
    if (values.size() % 12) throw Error("internal error: vec3s entries are 12 bytes");
    std::vector<uint32_t> bits(values.size() / 4);
    std::memcpy(bits.data(), values.data(), values.size());
    return coding::encodePlacedFloatVectors(bits, layout, places);
}

std::vector<uint8_t> decodeFloatVectors(std::span<const uint8_t> payload, std::span<const uint64_t> layout, uint64_t entries,
                                        std::span<const coding::BrickPlace> places, const std::string& what) {
    std::vector<uint32_t> bits(static_cast<size_t>(entries) * 3);
    coding::decodePlacedFloatVectors(payload, layout, places, bits, what);
    std::vector<uint8_t> out(bits.size() * 4);
    std::memcpy(out.data(), bits.data(), out.size());
    return out;
}

WindowDirectory readPredictedWindowDirectory(std::span<const uint8_t> payload, uint32_t valueSize, std::span<const uint64_t> layout,
                                             const std::string& what) {
    format::ByteReader r(payload, what);
    WindowDirectory dir;
    dir.valueSize = r.get<uint32_t>();
    if (dir.valueSize != valueSize) r.fail("holds " + std::to_string(dir.valueSize) + "-byte values, expected " + std::to_string(valueSize));
    dir.entries = r.get<uint64_t>();
    uint64_t layoutEntries = 0;
    for (uint64_t m : layout) layoutEntries += detail::layoutEntries(m);
    if (dir.entries != layoutEntries) r.fail("holds " + std::to_string(dir.entries) + " entries, the DAG " + std::to_string(layoutEntries));
    const uint64_t windowEntries = r.get<uint64_t>();
    if (!std::has_single_bit(windowEntries) || windowEntries < (uint64_t(1) << 10) || windowEntries > (uint64_t(1) << 30))
        r.fail("window of " + std::to_string(windowEntries) + " entries (a power of two from 2^10 to 2^30 is expected)");
    const uint64_t windows = r.get<uint64_t>();
    if (windows > r.remaining() / detail::kPredictedDirectoryEntryBytes) r.fail("window directory runs past the end");
    const size_t framesBegin = r.position(), directoryBegin = payload.size() - size_t(windows) * detail::kPredictedDirectoryEntryBytes;
    format::ByteReader d(payload.subspan(directoryBegin), what + " window directory");
    dir.windows.resize(size_t(windows));
    uint64_t storedTotal = 0, entryTotal = 0;
    size_t brick = 0;
    const uint64_t frameBytes = directoryBegin - framesBegin;
    for (uint64_t k = 0; k < windows; ++k) {
        WindowDirectory::Window& e = dir.windows[size_t(k)];
        e.stored = d.get<uint64_t>();
        e.raw = d.get<uint64_t>();
        e.entries = d.get<uint64_t>();
        if (e.stored > frameBytes || e.raw < e.stored || e.raw == 0 || !format::zstdCanProduce(e.stored, e.raw)) r.fail("window sizes are implausible");
        if (e.entries == 0 || e.entries > windowEntries + 63) r.fail("a window of " + std::to_string(e.entries) + " entries");
        // Window k holds the bricks whose first entry lies in [kE, (k+1)E).
        if (entryTotal / windowEntries != k || (entryTotal + e.entries - 1) / windowEntries > k + 1)
            r.fail("window " + std::to_string(k) + " does not hold the bricks that start in it");
        e.offset = framesBegin + storedTotal;
        e.firstEntry = entryTotal;
        storedTotal += e.stored;
        entryTotal += e.entries;
        if (storedTotal > frameBytes || entryTotal > dir.entries) continue;  // reported below
        // The window's brick instances.
        e.firstBrick = brick;
        uint64_t n = 0;
        while (brick < layout.size() && n < e.entries) n += detail::layoutEntries(layout[brick++]);
        e.bricks = brick - e.firstBrick;
        if (n != e.entries) r.fail("window " + std::to_string(k) + "'s " + std::to_string(e.entries) + " entries end inside a brick");
    }
    if (storedTotal != frameBytes) r.fail("windows hold " + std::to_string(frameBytes) + " bytes, the directory says " + std::to_string(storedTotal));
    if (entryTotal != dir.entries) r.fail("windows hold " + std::to_string(entryTotal) + " entries, the header says " + std::to_string(dir.entries));
    return dir;
}

WindowReference::WindowReference(std::vector<uint8_t> bytes, uint32_t valueSize, std::span<const uint64_t> layout,
                                 std::shared_ptr<const WindowReference> nextReference, std::string name)
    : payload(std::move(bytes)), next(std::move(nextReference)), depth(next ? next->depth + 1 : 1), what(std::move(name)) {
    if (depth > kMaxReferenceChain) throw Error(what + ": a chain of more than " + std::to_string(kMaxReferenceChain) + " grids, each the reference of the next");
    directory = readPredictedWindowDirectory(payload, valueSize, layout, what);
    offered_.resize(directory.windows.size());
}

std::vector<uint8_t> WindowReference::window(size_t k, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places) const {
    {
        std::lock_guard lock(mutex_);
        if (k >= offered_.size()) throw Error(what + ": has no window " + std::to_string(k));
        if (!offered_[k].empty()) return std::move(offered_[k]);  // handed out once
    }
    std::vector<uint8_t> values = decodePredictedWindow(payload, directory, k, layout, what, places, referenceWindows(next, layout, places));
    if (values.size() != directory.windows[k].entries * directory.valueSize) throw Error(what + " window " + std::to_string(k) + ": decoded to the wrong size");
    return values;
}

void WindowReference::offer(size_t k, std::span<const uint8_t> values) const {
    std::lock_guard lock(mutex_);
    if (k < offered_.size() && values.size() == directory.windows[k].entries * directory.valueSize) offered_[k].assign(values.begin(), values.end());
}

ReferenceWindow referenceWindows(const std::shared_ptr<const WindowReference>& reference, std::span<const uint64_t> layout,
                                 std::span<const coding::BrickPlace> places) {
    if (!reference) return {};
    return [reference, layout, places](size_t k) { return reference->window(k, layout, places); };
}

std::vector<uint8_t> decodePredictedWindow(std::span<const uint8_t> payload, const WindowDirectory& dir, size_t k, std::span<const uint64_t> layout,
                                           const std::string& what, std::span<const coding::BrickPlace> places, const ReferenceWindow& reference) {
    const WindowDirectory::Window& e = dir.windows.at(k);
    const std::string where = what + " window " + std::to_string(k);
    const std::vector<uint8_t> raw = windowRawBytes(payload, e, where);
    const std::span<const uint8_t> body = std::span<const uint8_t>(raw).subspan(1);
    if (raw[0] == detail::kReferencedContextCoding || raw[0] == detail::kReferencedRescaledFloatCoding) {
        // Codings 19 and 20 with the reference's window k as neighbours.
        if (!reference) throw Error(where + ": is coded with a series' reference, and its layer names none");
        if (dir.valueSize != 4) throw Error(where + ": a referenced window of " + std::to_string(dir.valueSize) + "-byte values (4 expected)");
        if (places.size() != layout.size()) throw Error(where + ": internal error: the window needs its bricks' places");
        const std::vector<uint8_t> t = reference(k);
        if (t.size() != e.entries * 4) throw Error(where + ": its reference window holds " + std::to_string(t.size() / 4) + " entries, expected " + std::to_string(e.entries));
        const std::span<const uint64_t> bricks = layout.subspan(size_t(e.firstBrick), size_t(e.bricks));
        const auto placesHere = places.subspan(size_t(e.firstBrick), size_t(e.bricks));
        if (raw[0] == detail::kReferencedRescaledFloatCoding) return decodeRescaledFloats(body, bricks, e.entries, where, placesHere, 4, true, t);
        std::vector<int32_t> taps(t.size() / 4);
        std::memcpy(taps.data(), t.data(), t.size());
        return decodeContextChannel(body, bricks, e.entries, where, placesHere, false, coding::spatialOrderOf(4), 4, 1, true, taps);
    }
    if (raw[0] == detail::kPaletteCoding) {
        const PaletteChannel c = deserializePalette(body, where);
        if (c.valueSize != dir.valueSize || c.entryCount != e.entries)
            throw Error(where + ": holds " + std::to_string(c.entryCount) + " entries of " + std::to_string(c.valueSize) + " bytes, expected " +
                        std::to_string(e.entries) + " of " + std::to_string(dir.valueSize));
        return c.decodeAll();
    }
    const std::span<const uint64_t> bricks = layout.subspan(size_t(e.firstBrick), size_t(e.bricks));
    if (raw[0] == detail::kPredictedCoding) return decodePredicted(body, dir.valueSize, bricks, where);
    const uint8_t c = raw[0];
    if (c == detail::kContextCoding || c == detail::kPlacedContextCoding || c == detail::kPlacedLabelCoding || c == detail::kSpatialContextCoding ||
        c == detail::kSpatialLabelCoding || c == detail::kFittedContextCoding || c == detail::kWideContextCoding || c == detail::kBandedContextCoding ||
        c == detail::kShapedLabelCoding || c == detail::kTiledLabelCoding || c == detail::kTiledContextCoding) {
        if (dir.valueSize != 4) throw Error(where + ": a context-coded window of " + std::to_string(dir.valueSize) + "-byte values (int32 only)");
        if (c == detail::kContextCoding) return decodeContextChannel(body, bricks, e.entries, where);
        if (places.size() != layout.size()) throw Error(where + ": internal error: the window needs its bricks' places");
        if (c == detail::kShapedLabelCoding || c == detail::kTiledLabelCoding)  // label model generation 2 or 3, bricks in raster order (LabelCoder.h)
            return decodeContextChannel(body, bricks, e.entries, where, places.subspan(size_t(e.firstBrick), size_t(e.bricks)), true,
                                        coding::BrickOrder::Raster, coding::kLatestIntModel, c == detail::kTiledLabelCoding ? 3 : 2);
        if (c == detail::kTiledContextCoding)  // model generation 4 with tiles as neighbours
            return decodeContextChannel(body, bricks, e.entries, where, places.subspan(size_t(e.firstBrick), size_t(e.bricks)), false,
                                        coding::spatialOrderOf(4), 4, 1, true);
        const int model = c == detail::kBandedContextCoding ? 4 : c == detail::kWideContextCoding ? 3 : c == detail::kFittedContextCoding ? 2 : 1;
        const bool spatial = c == detail::kSpatialContextCoding || c == detail::kSpatialLabelCoding || model >= 2;
        return decodeContextChannel(body, bricks, e.entries, where, places.subspan(size_t(e.firstBrick), size_t(e.bricks)),
                                    c == detail::kPlacedLabelCoding || c == detail::kSpatialLabelCoding,
                                    spatial ? coding::spatialOrderOf(model) : coding::BrickOrder::Attribute, model);
    }
    if (raw[0] == detail::kRescaledFloatCoding || raw[0] == detail::kFittedRescaledFloatCoding || raw[0] == detail::kWideRescaledFloatCoding ||
        raw[0] == detail::kBandedRescaledFloatCoding || raw[0] == detail::kTiledRescaledFloatCoding) {
        if (dir.valueSize != 4) throw Error(where + ": rescaled floats of " + std::to_string(dir.valueSize) + "-byte values (float32 only)");
        if (places.size() != layout.size()) throw Error(where + ": internal error: the window needs its bricks' places");
        return decodeRescaledFloats(body, bricks, e.entries, where, places.subspan(size_t(e.firstBrick), size_t(e.bricks)),
                                    raw[0] == detail::kBandedRescaledFloatCoding || raw[0] == detail::kTiledRescaledFloatCoding ? 4
                                    : raw[0] == detail::kWideRescaledFloatCoding                                                 ? 3
                                    : raw[0] == detail::kFittedRescaledFloatCoding                                               ? 2
                                                                                                                                 : 1,
                                    raw[0] == detail::kTiledRescaledFloatCoding);
    }
    if (raw[0] == detail::kFloatCoding || raw[0] == detail::kFloatIntegerCoding) {  // float32 bits predicted, or their order's integers
        const bool integers = raw[0] == detail::kFloatIntegerCoding;
        if (dir.valueSize != 4)
            throw Error(where + ": " + (integers ? "float integers" : "predicted floats") + " of " + std::to_string(dir.valueSize) + "-byte values (float32 only)");
        if (places.size() != layout.size()) throw Error(where + ": internal error: the window needs its bricks' places");
        std::vector<uint32_t> bits(size_t(e.entries));
        const auto placesHere = places.subspan(size_t(e.firstBrick), size_t(e.bricks));
        if (integers) coding::decodePlacedFloatIntegers(body, bricks, placesHere, bits, where);
        else coding::decodePlacedFloats(body, bricks, placesHere, bits, where);
        std::vector<uint8_t> out(bits.size() * 4);
        std::memcpy(out.data(), bits.data(), out.size());
        return out;
    }
    if (raw[0] == detail::kFloatVectorCoding) {
        if (dir.valueSize != 12) throw Error(where + ": predicted vectors of " + std::to_string(dir.valueSize) + "-byte values (vec3s only)");
        if (places.size() != layout.size()) throw Error(where + ": internal error: the window needs its bricks' places");
        return decodeFloatVectors(body, bricks, e.entries, places.subspan(size_t(e.firstBrick), size_t(e.bricks)), where);
    }
    throw Error(where + ": unknown coding " + std::to_string(raw[0]));
}

std::vector<uint8_t> decodePredictedWindows(std::span<const uint8_t> payload, uint32_t valueSize, std::span<const uint64_t> layout,
                                            const std::string& what, std::span<const coding::BrickPlace> places, const ParallelFor& parallel,
                                            const ReferenceWindow& reference, const WindowReference* offerTo) {
    const WindowDirectory dir = readPredictedWindowDirectory(payload, valueSize, layout, what);
    std::vector<uint8_t> out(size_t(dir.entries * valueSize));  // entries matched the DAG's layout
    // The windows through `parallel` (in any order, each into its place: the
    // directory gave each window's first entry and count); a failure is
    // reported as the lowest failing window's, whatever the thread count.
    std::vector<std::exception_ptr> failed(dir.windows.size());
    const auto one = [&](size_t k) {
        try {
            const std::vector<uint8_t> values = decodePredictedWindow(payload, dir, k, layout, what, places, reference);
            if (values.size() != dir.windows[k].entries * valueSize) throw Error(what + " window " + std::to_string(k) + ": decoded to the wrong size");
            std::memcpy(out.data() + dir.windows[k].firstEntry * valueSize, values.data(), values.size());
            if (offerTo) offerTo->offer(k, values);
        } catch (...) {
            failed[k] = std::current_exception();
        }
    };
    if (parallel) parallel(dir.windows.size(), one);
    else for (size_t k = 0; k < dir.windows.size(); ++k) one(k);
    for (const std::exception_ptr& e : failed)
        if (e) std::rethrow_exception(e);
    return out;
}

} // namespace vdbdag::attributes

