// See PredictedWindows.h: the writer of predicted windows (each window coded
// on its own core as palettes or residuals, spilled to scratch when large).
// Reading them: PredictedWindows.cpp.
#include "src/attributes/PredictedWindows.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "src/attributes/ContextChannel.h"
#include "src/attributes/PaletteCompressor.h"
#include "src/attributes/PredictedChannel.h"
#include "src/attributes/RescaledFloats.h"
#include "src/coding/CodeAside.h"
#include "src/coding/FloatIntegerCoder.h"
#include "src/coding/FloatValueCoder.h"
#include "src/coding/LabelCoder.h"
#include "src/format/ByteIO.h"
#include "src/format/ZstdFrame.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {
namespace {

constexpr uint64_t kSmallWindowBytes = uint64_t(4) << 20;  // level 9 up to this, then 3 (the container's rule)
constexpr size_t kHeaderBytes = 4 + 8 + 8 + 8;

// Whether zstd is worth trying on a window's raw bytes (the writer keeps
// them raw where zstd does not shrink them). A range-coded window of more
// than kProbeBytes is tried only when zstd's fastest level shrinks its
// first kProbeBytes by 1 %: such windows are near-random bytes that level 9
// cannot shrink either, and trying was 8 % of a level set's encode (the
// bunny's 1.7 MB float windows). Small range-coded windows can shrink (a
// cube level set's 1,947 bytes to 334) and are always tried, as are
// palettes and brick residuals, which are coded for zstd.
constexpr size_t kProbeBytes = size_t(64) << 10;
bool zstdMayShrink(std::span<const uint8_t> raw) {
    if (raw.empty() || raw[0] == detail::kPaletteCoding || raw[0] == detail::kPredictedCoding || raw.size() <= kProbeBytes) return true;
    return format::zstdFastSize(raw.first(kProbeBytes)) * 100 < kProbeBytes * 99;
}

// Whether a window looks like labels: most entries repeat the one before
// (in attribute order, neighbours mostly), as regions of one label do and
// a scan's noise does not. Only such windows are also coded as labels.
bool looksLikeLabels(std::span<const uint8_t> values) {
    const size_t n = values.size() / 4;
    if (n < 2) return false;
    size_t repeats = 0;
    for (size_t i = 1; i < n; ++i) repeats += std::memcmp(values.data() + 4 * i, values.data() + 4 * (i - 1), 4) == 0;
    return repeats * 4 >= (n - 1) * 3;
}

// Whether a window's palettes are not worth building: estimated from its
// first sixteenth, 16 times the sample's palettes (zstd's fast estimate)
// exceed 1.5 times the best coding found (1.2 times for float windows). A
// palette's indices grow with its entries and only its material array is
// shared, so the estimate errs high by at most that array; a scan's noise
// never lets palettes win, and building them was a tenth of an encode. On
// float windows (level sets, fogs, smoke) the estimate came within 0.96 to
// 1.16 of the palettes' size, so 1.2 leaves them out only where they lose,
// and a half-float smoke's encode no longer builds them (smoke1: estimate
// 1.23 times the predicted floats). Small windows and windows that look
// like labels build theirs.
bool palettesCannotWin(std::span<const uint8_t> values, uint32_t vs, uint64_t bestSize, bool labelsLike, bool floats) {
    constexpr size_t kSampleEntries = size_t(1) << 14;  // the smallest sample worth estimating from
    const size_t n = values.size() / vs;
    if (labelsLike || bestSize == UINT64_MAX || n / 16 < kSampleEntries) return false;
    const uint64_t sample = format::zstdFastSize(serializePalette(compressPalette(values.first(n / 16 * vs), vs)));
    return 16 * sample > bestSize + (floats ? bestSize / 5 : bestSize / 2);
}

// The window's first bricks that a choice between two codings is decided
// on: an eighth of its entries, at least 2^14 (all of a smaller window).
struct WindowSample {
    size_t bricks = 0;
    uint64_t entries = 0;
};
WindowSample firstEighth(std::span<const uint64_t> layout, uint64_t entries) {
    const uint64_t want = std::max<uint64_t>(entries / 8, uint64_t(1) << 14);
    WindowSample s;
    while (s.bricks < layout.size() && s.entries < want) s.entries += coding::layoutEntryCount(layout.subspan(s.bricks++, 1));
    return s;
}

// Whether a float32 window's integers of their order (coding 12,
// coding/FloatIntegerCoder.h) code smaller than its predicted bits (coding
// 8). Tried only on reduced-precision floats (at least 8 zero low bits in
// every entry: half floats have 13): on full-precision ones the integers
// lost by 1.3 to 8 times on every level set and fog tried. Decided on the
// window's first bricks (an eighth of its entries, at least 2^14; all of a
// smaller window), each way, so the window itself is coded once.
bool floatIntegersWin(std::span<const uint32_t> bits, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places) {
    constexpr unsigned kReducedPrecision = 8;
    if (places.empty() || bits.empty() || coding::floatZeroLowBits(bits) < kReducedPrecision) return false;
    const WindowSample w = firstEighth(layout, bits.size());
    const auto sample = std::span<const uint32_t>(bits).first(size_t(w.entries));
    const auto sampleLayout = layout.first(w.bricks);
    const auto samplePlaces = places.first(w.bricks);
    size_t integers = 0, floats = 0;  // side by side: a window coded while the other cores idle is a grid's only one
    tbb::parallel_invoke([&] { integers = coding::encodePlacedFloatIntegers(sample, sampleLayout, samplePlaces).size(); },
                         [&] { floats = coding::encodePlacedFloats(sample, sampleLayout, samplePlaces).size(); });
    return integers < floats;
}

// A window's entries as labels, as a writer codes them today: coding 18,
// which PredictedWindows.cpp reads as label model generation 3 with the
// bricks in raster order (coding/LabelCoder.h). A newer generation needs a
// coding of its own.
std::vector<uint8_t> encodeLabels(std::span<const uint8_t> values, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places) {
    static_assert(coding::kLatestLabelModel == 3, "a new label model generation needs a window coding of its own");
    return encodeContextChannel(values, layout, places, true, coding::BrickOrder::Raster, coding::kLatestIntModel, 3);
}

// Whether the least-squares model (coding 13) may code an int32 window
// that looks like labels smaller than the label coder (coding 18, coded
// whole already: it is the fast one): only where it does on a sample of
// the window's bricks. Where the labels win there, the model is not run on
// the window (coding both doubled an atlas's encode); where it wins, both
// are coded and the smaller kept, since a sample of background favours the
// model and misleads (labels256: 72,347 bytes kept; 82,004 had the window's
// first eighth decided alone).
bool modelMayBeatLabels(std::span<const uint8_t> values, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places) {
    // Eight runs of bricks spread over the window, each about a 64th of its
    // entries: together an eighth, from everywhere rather than its start.
    constexpr size_t kRuns = 8;
    std::vector<uint64_t> first(layout.size() + 1, 0);  // entries before each brick
    for (size_t b = 0; b < layout.size(); ++b) first[b + 1] = first[b] + coding::layoutEntryCount(layout.subspan(b, 1));
    const uint64_t total = first.back(), run = std::max<uint64_t>(total / 64, uint64_t(1) << 11);
    if (total <= kRuns * run) return true;  // the sample would be the whole window: code it both ways once
    std::vector<uint8_t> sample;
    std::vector<uint64_t> sampleLayout;
    std::vector<coding::BrickPlace> samplePlaces;
    size_t next = 0;  // no brick twice
    for (size_t r = 0; r < kRuns; ++r) {
        size_t b = std::max(next, size_t(std::upper_bound(first.begin(), first.end(), total * r / kRuns) - first.begin()) - 1);
        for (const uint64_t end = first[b] + run; b < layout.size() && first[b] < end; ++b) {
            sampleLayout.push_back(layout[b]);
            samplePlaces.push_back(places[b]);
            sample.insert(sample.end(), values.begin() + ptrdiff_t(first[b] * 4), values.begin() + ptrdiff_t(first[b + 1] * 4));
        }
        next = b;
    }
    const bool tiles = std::find(sampleLayout.begin(), sampleLayout.end(), uint64_t(0)) != sampleLayout.end();
    size_t model = 0, labels = 0;
    tbb::parallel_invoke(
        [&] {
            model = encodeContextChannel(sample, sampleLayout, samplePlaces, false, coding::spatialOrderOf(coding::kLatestIntModel), coding::kLatestIntModel, 1,
                                         tiles)
                        .size();
        },
        [&] { labels = encodeLabels(sample, sampleLayout, samplePlaces).size(); });
    return model < labels;
}

// A window's raw bytes: its coding byte, then the smallest of its entries
// coded from their neighbours (int32 context-modelled, range coded already,
// with neighbours across bricks when their places are known, and as labels
// too when the window looks like labels; int64 brick MED residuals, by
// zstd's estimate; a float32 window's bits predicted in 3-D, and its
// lattice's integers when it has one; a vec3s window's components' bits)
// and its palettes
// (by zstd's fast estimate; they win a tie), unless a sample says they
// cannot win.
// `aside`: the integer coders may range-code on a thread beside their walk
// (coding/CodeAside.h; the same bytes).
std::vector<uint8_t> codeWindow(std::span<const uint8_t> values, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places,
                                uint32_t vs, const std::optional<FloatChannel>& floats, bool aside) {
    std::vector<uint8_t> best;
    uint64_t bestSize = UINT64_MAX;
    uint8_t coding = detail::kPaletteCoding;
    const auto consider = [&](std::vector<uint8_t>&& payload, uint64_t size, uint8_t kind) {
        if (size > bestSize || (size == bestSize && kind != detail::kPaletteCoding)) return;
        best = std::move(payload), bestSize = size, coding = kind;
    };
    bool labelsLike = false;
    if (floats && vs == 12) {  // vec3s entries: each component's bits predicted, or their palettes
        std::vector<uint8_t> components = encodeFloatVectors(values, layout, places);
        const uint64_t size = components.size();
        consider(std::move(components), size, detail::kFloatVectorCoding);
    } else if (floats) {  // float32 entries: their bits predicted (or their order's integers), their lattice's integers, their palettes
        std::vector<uint32_t> bits(values.size() / 4);
        std::memcpy(bits.data(), values.data(), bits.size() * 4);
        if (floatIntegersWin(bits, layout, places)) {
            std::vector<uint8_t> integers = coding::encodePlacedFloatIntegers(bits, layout, places, aside);
            const uint64_t size = integers.size();
            consider(std::move(integers), size, detail::kFloatIntegerCoding);
        } else {
            std::vector<uint8_t> predicted = coding::encodePlacedFloats(bits, layout, places);
            const uint64_t size = predicted.size();
            consider(std::move(predicted), size, detail::kFloatCoding);
        }
        if (floats->lattice) {
            // A window with tiles walks them as neighbours (coding 20); one without is coding 16, the same stream.
            const bool tiles = std::find(layout.begin(), layout.end(), uint64_t(0)) != layout.end();
            if (std::optional<std::vector<uint8_t>> integers = encodeRescaledFloats(values, layout, places, *floats->lattice, coding::kLatestIntModel, tiles, aside)) {
                const uint64_t latticeSize = integers->size();
                consider(std::move(*integers), latticeSize, tiles ? detail::kTiledRescaledFloatCoding : detail::kBandedRescaledFloatCoding);
            }
        }
    } else if (vs == 4) {
        const bool placed = !places.empty();
        labelsLike = placed && looksLikeLabels(values);
        if (labelsLike) {
            std::vector<uint8_t> labels = encodeLabels(values, layout, places);
            const uint64_t labelSize = labels.size();
            consider(std::move(labels), labelSize, detail::kTiledLabelCoding);
        }
        if (!labelsLike || modelMayBeatLabels(values, layout, places)) {
            // A window with tiles walks them as neighbours (coding 19); one
            // without is coding 15, the same stream.
            static_assert(coding::kLatestIntModel == 4, "coding 19 is generation 4's walk with tiles");
            const bool tiles = placed && std::find(layout.begin(), layout.end(), uint64_t(0)) != layout.end();
            std::vector<uint8_t> numeric =
                encodeContextChannel(values, layout, places, false, coding::spatialOrderOf(coding::kLatestIntModel), coding::kLatestIntModel, 1, tiles, aside);
            const uint64_t size = numeric.size();
            consider(std::move(numeric), size, tiles ? detail::kTiledContextCoding : placed ? detail::kBandedContextCoding : detail::kContextCoding);
        }
    } else {
        std::vector<uint8_t> predicted = encodePredicted(values, vs, layout);
        const uint64_t size = format::zstdFastSize(predicted);
        consider(std::move(predicted), size, detail::kPredictedCoding);
    }
    if (!palettesCannotWin(values, vs, bestSize, labelsLike, floats.has_value())) {
        std::vector<uint8_t> palette = serializePalette(compressPalette(values, vs));
        const uint64_t size = format::zstdFastSize(palette);
        consider(std::move(palette), size, detail::kPaletteCoding);
    }
    std::vector<uint8_t> raw;
    raw.reserve(best.size() + 1);
    raw.push_back(coding);
    raw.insert(raw.end(), best.begin(), best.end());
    return raw;
}

// A window's raw bytes as stored: one zstd frame where that is smaller.
std::vector<uint8_t> storedWindow(std::vector<uint8_t>&& raw) {
    std::vector<uint8_t> stored;
    if (zstdMayShrink(raw)) stored = format::zstdCompressIfSmaller(raw, {raw.size() <= kSmallWindowBytes ? 9 : 3, /*checksum*/ true, 0});
    if (stored.empty()) stored = std::move(raw);
    return stored;
}

} // namespace

std::optional<std::vector<uint8_t>> referencePredictedWindows(std::span<const uint8_t> payload, const ReferenceWindow& own, const ReferenceWindow& reference,
                                                              uint32_t valueSize, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places,
                                                              const std::string& what, uint64_t& referenced) {
    referenced = 0;
    const WindowDirectory dir = readPredictedWindowDirectory(payload, valueSize, layout, what);
    if (valueSize != 4 || places.size() != layout.size()) return std::nullopt;
    // Each window of the walks that take a reference (codings 15, 16, 19,
    // 20: 15 and 16 are 19 and 20 on a layout without tiles) coded again
    // with it, in parallel; the smaller kept.
    std::vector<std::vector<uint8_t>> stored(dir.windows.size());
    std::vector<uint64_t> raws(dir.windows.size());
    tbb::parallel_for(size_t(0), dir.windows.size(), [&](size_t k) {
        const WindowDirectory::Window& e = dir.windows[k];
        const std::string where = what + " window " + std::to_string(k);
        const uint8_t coding = windowRawBytes(payload, e, where).at(0);
        const bool integers = coding == detail::kTiledContextCoding || coding == detail::kBandedContextCoding;
        const bool lattice = coding == detail::kTiledRescaledFloatCoding || coding == detail::kBandedRescaledFloatCoding;
        if (!integers && !lattice) return;
        const std::vector<uint8_t> values = own(k);
        const std::vector<uint8_t> t = reference(k);
        if (t.size() != values.size() || values.size() != e.entries * 4) return;  // windows cut otherwise: this one stays as it is
        const std::span<const uint64_t> bricks = layout.subspan(size_t(e.firstBrick), size_t(e.bricks));
        const auto placesHere = places.subspan(size_t(e.firstBrick), size_t(e.bricks));
        std::vector<uint8_t> raw;
        if (integers) {
            std::vector<int32_t> taps(t.size() / 4);
            std::memcpy(taps.data(), t.data(), t.size());
            raw = encodeContextChannel(values, bricks, placesHere, false, coding::spatialOrderOf(4), 4, 1, true, false, taps);
            raw.insert(raw.begin(), detail::kReferencedContextCoding);
        } else {
            const std::vector<uint8_t> own = windowRawBytes(payload, e, where);
            format::ByteReader r(std::span<const uint8_t>(own).subspan(1), where);
            ValueRescale rescale;
            rescale.slope = r.get<double>();  // the window's own lattice (RescaledFloats.h)
            rescale.intercept = r.get<double>();
            std::optional<std::vector<uint8_t>> coded = encodeRescaledFloats(values, bricks, placesHere, rescale, 4, true, false, t);
            if (!coded) return;
            raw = std::move(*coded);
            raw.insert(raw.begin(), detail::kReferencedRescaledFloatCoding);
        }
        const uint64_t rawSize = raw.size();
        std::vector<uint8_t> candidate = storedWindow(std::move(raw));
        if (candidate.size() < e.stored) {
            stored[k] = std::move(candidate);
            raws[k] = rawSize;
        }
    });
    format::ByteWriter out;
    out.putBytes(payload.first(kHeaderBytes));
    format::ByteWriter directory;
    for (size_t k = 0; k < dir.windows.size(); ++k) {
        const WindowDirectory::Window& e = dir.windows[k];
        referenced += !stored[k].empty();
        if (stored[k].empty()) out.putBytes(payload.subspan(size_t(e.offset), size_t(e.stored)));
        else out.putBytes(stored[k]);
        directory.put<uint64_t>(stored[k].empty() ? e.stored : stored[k].size());
        directory.put<uint64_t>(stored[k].empty() ? e.raw : raws[k]);
        directory.put<uint64_t>(e.entries);
    }
    if (referenced == 0) return std::nullopt;
    out.putBytes(directory.bytes());
    return out.take();
}

PredictedWindowWriter::PredictedWindowWriter(uint32_t valueSize, unsigned parallel, const std::string& spillNear, uint64_t spillInMemory,
                                             std::optional<FloatChannel> floats)
    : valueSize_(valueSize),
      windowEntries_(floats && !floats->lattice ? kFloatWindowEntries : kValueWindowEntries),
      floats_(floats),
      parallel_(parallel ? parallel : unsigned(std::max(1, tbb::info::default_concurrency()))) {
    if (!floats && valueSize != 4 && valueSize != 8) throw Error("internal error: predicted windows hold 4- or 8-byte integers");
    if (floats && valueSize != 4 && valueSize != 12) throw Error("internal error: predicted float windows hold float32 or vec3s entries");
    const uint8_t zeros[kHeaderBytes] = {};
    if (!spillNear.empty()) {
        spill_ = std::make_shared<ScratchFile>(spillNear, spillInMemory);
        spill_->append(zeros, kHeaderBytes);
    } else {
        payload_.assign(zeros, zeros + kHeaderBytes);
    }
}

void PredictedWindowWriter::beginShare(uint64_t firstEntry, bool endsLayer) {
    if (entries_ || !pending_.empty() || !directory_.empty() || spill_) throw Error("internal error: a share begins before the first entry");
    share_ = true;
    endsLayer_ = endsLayer;
    entries_ = firstEntry;
    headEnd_ = (firstEntry + windowEntries_ - 1) / windowEntries_ * windowEntries_;
    head_.window = firstEntry / windowEntries_;
    windows_ = headEnd_ / windowEntries_;
    payload_.clear();  // coded windows only: process 0 writes the header
}

void PredictedWindowWriter::add(std::span<const uint8_t> values, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places) {
    if (rangeType_) range_.add(*rangeType_, values);
    if (!layout.empty()) {
        if (!places.empty() && places.size() != layout.size()) throw Error("internal error: a layout and its places differ in length");
        if (placed_ && *placed_ != !places.empty()) throw Error("internal error: brick places given in some calls only");
        if (floats_ && places.empty()) throw Error("internal error: floats are coded with their bricks' places");
        placed_ = !places.empty();
    }
    size_t at = 0;  // byte position in `values`
    size_t i = 0;
    // The bricks that start before this share's first window: its head.
    while (share_ && i < layout.size() && entries_ < headEnd_) {
        const uint64_t n = detail::layoutEntries(layout[i]);
        if (at + n * valueSize_ > values.size()) throw Error("internal error: the layout holds more entries than the values given");
        if (!places.empty()) head_.places.push_back(places[i]);
        head_.layout.push_back(layout[i++]);
        head_.values.insert(head_.values.end(), values.begin() + long(at), values.begin() + long(at + n * valueSize_));
        at += size_t(n * valueSize_);
        entries_ += n;
    }
    while (i < layout.size()) {
        // A brick instance belongs to the window its first entry falls in.
        const uint64_t window = entries_ / windowEntries_;
        if (pending_.empty() || window != windows_ - 1) {
            if (window != windows_) throw Error("internal error: a predicted window skipped");
            if (pending_.size() == parallel_) codePending();  // every pending window is full
            pending_.emplace_back();
            pending_.back().values.reserve(size_t((windowEntries_ + 64) * valueSize_));  // untouched until filled: never copied
            ++windows_;
        }
        Window& w = pending_.back();
        // The instances that start in this window.
        const uint64_t windowEnd = (window + 1) * windowEntries_;
        size_t j = i;
        uint64_t n = 0;
        while (j < layout.size() && entries_ + n < windowEnd) n += detail::layoutEntries(layout[j++]);
        if (at + n * valueSize_ > values.size()) throw Error("internal error: the layout holds more entries than the values given");
        w.layout.insert(w.layout.end(), layout.begin() + long(i), layout.begin() + long(j));
        if (!places.empty()) w.places.insert(w.places.end(), places.begin() + long(i), places.begin() + long(j));
        w.values.insert(w.values.end(), values.begin() + long(at), values.begin() + long(at + n * valueSize_));
        w.entries += n;
        entries_ += n;
        at += size_t(n * valueSize_);
        i = j;
    }
    if (at != values.size()) throw Error("internal error: the values given hold more entries than the layout");
}

void PredictedWindowWriter::codePending() {
    std::vector<std::vector<uint8_t>> stored(pending_.size());
    std::vector<uint64_t> rawBytes(pending_.size());
    // The integer coders range-code beside their walk (coding/CodeAside.h)
    // where a thread --threads allows would otherwise idle: fewer windows
    // large enough for it are coded together than there are threads (a grid
    // of one window, a layer's last). Its threads then stay within
    // --threads. The float coder never does: its coding is too small a part
    // of its time (aside, the bunny level set encoded 5 % slower,
    // unnamed_levelset 7 %).
    size_t large = 0;
    for (const Window& w : pending_) large += w.entries >= coding::kCodeAsideSamples;
    const bool aside = large < tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    tbb::parallel_for(size_t(0), pending_.size(), [&](size_t i) {
        std::vector<uint8_t> raw = codeWindow(pending_[i].values, pending_[i].layout, pending_[i].places, valueSize_, floats_, aside);
        std::vector<uint8_t>().swap(pending_[i].values);
        std::vector<uint64_t>().swap(pending_[i].layout);
        std::vector<coding::BrickPlace>().swap(pending_[i].places);
        rawBytes[i] = raw.size();
        stored[i] = storedWindow(std::move(raw));
    });
    for (size_t i = 0; i < pending_.size(); ++i) {
        appendWindow(payload_, spill_.get(), stored[i]);
        directory_.push_back({stored[i].size(), rawBytes[i], pending_[i].entries});
    }
    pending_.clear();
}

ShareWindows PredictedWindowWriter::finishShare() {
    if (!share_) throw Error("internal error: finishShare without beginShare");
    ShareWindows out;
    // The last window is whole here when the next share's first brick
    // starts past it, or this share ends the layer.
    if (!pending_.empty() && !endsLayer_ && entries_ < windows_ * windowEntries_) {
        out.tail.window = windows_ - 1;
        out.tail.values = std::move(pending_.back().values);
        out.tail.layout = std::move(pending_.back().layout);
        out.tail.places = std::move(pending_.back().places);
        pending_.pop_back();
    }
    codePending();
    out.firstWindow = headEnd_ / windowEntries_;
    for (const Directory& d : directory_) out.directory.push_back({d.stored, d.raw, d.entries});
    out.coded = std::move(payload_);
    out.head = std::move(head_);
    if (rangeType_) out.range = range_;
    directory_.clear();
    return out;
}

void PredictedWindowWriter::addShare(const ShareWindows& share) {
    if (rangeType_ && share.range) range_.merge(*rangeType_, *share.range);
    add(share.head.values, share.head.layout, share.head.places);
    uint64_t at = 0;
    for (size_t j = 0; j < share.directory.size(); ++j) {
        const ShareWindows::Coded& c = share.directory[j];
        if (c.stored > share.coded.size() - at) throw Error("internal error: a process's coded windows are cut short");
        addCoded(share.firstWindow + j, c, std::span<const uint8_t>(share.coded).subspan(size_t(at), size_t(c.stored)));
        at += c.stored;
    }
    add(share.tail.values, share.tail.layout, share.tail.places);
}

void PredictedWindowWriter::addCoded(uint64_t window, const ShareWindows::Coded& coded, std::span<const uint8_t> bytes) {
    if (entries_ / windowEntries_ != window || windows_ > window || bytes.size() != coded.stored)
        throw Error("internal error: a coded window out of place");
    codePending();
    appendWindow(payload_, spill_.get(), bytes);
    directory_.push_back({coded.stored, coded.raw, coded.entries});
    entries_ += coded.entries;
    windows_ = window + 1;
}

ValueWindowsPayload PredictedWindowWriter::finish() {
    if (!pending_.empty()) codePending();
    format::ByteWriter head;
    head.put<uint32_t>(valueSize_);
    head.put<uint64_t>(entries_);
    head.put<uint64_t>(windowEntries_);
    head.put<uint64_t>(directory_.size());
    format::ByteWriter dir;
    for (const Directory& d : directory_) {
        dir.put<uint64_t>(d.stored);
        dir.put<uint64_t>(d.raw);
        dir.put<uint64_t>(d.entries);
    }
    directory_.clear();
    ValueWindowsPayload out = sealWindows(std::move(payload_), std::move(spill_), head.bytes(), dir.bytes());
    out.predicted = true;
    if (rangeType_) out.range = range_;
    return out;
}

std::vector<uint8_t> encodePredictedWindows(std::span<const uint8_t> values, uint32_t valueSize, std::span<const uint64_t> layout,
                                            std::span<const coding::BrickPlace> places, std::optional<FloatChannel> floats) {
    PredictedWindowWriter writer(valueSize, 0, "", 0, floats);
    writer.add(values, layout, places);
    return std::move(writer.finish().bytes);
}

} // namespace vdbdag::attributes
