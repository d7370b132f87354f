// An integer value channel (int32 / int64) at rest in windows, each coded
// on its own as whichever is smaller: its palettes (PaletteChannel.h) or its
// brick-predicted residuals (PredictedChannel.h). A float32 channel
// (FloatChannel) too: its windows are palettes, its float bits predicted in
// 3-D (coding/FloatValueCoder.h) or, when its values lie on a rescale
// lattice (GridRecord::rescale), the lattice's integers (RescaledFloats.h).
// The windowed form of all of them, so an encoder of a dense scan holds one
// window per core, never the whole channel (ValueWindows.h does the same
// for palettes alone).
//
// The predictor reads inside a 4^3 brick, so a window holds whole brick
// instances: window k holds the instances (and solid nodes) whose first
// entry lies in [k E, (k+1) E), E = kValueWindowEntries (kFloatWindowEntries
// for a float channel without a lattice: its coder is slower, so its windows
// are smaller and more of them run in parallel, for 0.3 % in size; a
// lattice's integers code 0.5 % smaller in the larger windows), so it starts within
// 63 entries after kE. The cuts depend on the entries and the DAG's layout
// only, never on how the entries arrived, the memory limit, the thread
// count, or the windows before (a process can cut its own share). The bytes
// do not either. Each window's prediction starts afresh (the previous entry
// of its first brick is 0).
//
// Payload of a PredictedWindows / InactivePredictedWindows section (stored
// as it is, its frames are compressed already):
//   u32 value size (4|8), u64 entries, u64 window entries (the nominal
//   size, a power of two), u64 window count W,
//   the W windows back to back,
//   W x (u64 stored bytes, u64 raw bytes, u64 entries), the directory, last.
// A window's raw bytes are u8 coding (0: serializePalette bytes of its
// entries; 1: encodePredicted bytes over its bricks; 2: int32 only,
// encodeContextChannel bytes over its bricks, ContextChannel.h; 3: the same
// with neighbours across bricks, over its bricks and their places; 4: the
// same payload with the entries coded as labels, coding/LabelCoder.h; 5:
// float32 only, encodeRescaledFloats bytes over its bricks and their
// places, RescaledFloats.h; 6 and 7: codings 3 and 4 with the bricks
// visited in spatial order, coding::BrickOrder; 8: float32 only,
// encodePlacedFloats bytes over its bricks and their places, coding/FloatValueCoder.h; 9: vec3s only, encodeFloatVectors
// bytes: the three components in one stream; 10 and 11: codings 6 and 5
// with the integers' model generation 2, the least-squares fit,
// coding/LeastSquaresPredictor.h; 12-16: FORMAT.md 8.2-8.5; 17: coding 7's
// payload with the labels coded by label model generation 2 and the bricks
// visited in raster order inside 32^3 blocks, coding/LabelCoder.h; 18: the
// same with label model generation 3, tiles as neighbours; 19: coding 15
// with tiles as neighbours; 20: coding 16 with tiles as neighbours; 21 and
// 22: codings 19 and 20 with a series' reference, the same window of an
// earlier grid (WindowReference, below)) then that payload;
// stored == raw: as they are, else one zstd frame of them that declares the
// raw size and carries zstd's checksum.
#pragma once
#include <bit>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "src/attributes/ValueWindows.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::attributes {

inline constexpr uint64_t kFloatWindowEntries = uint64_t(1) << 20;

namespace detail {  // the layout above, shared by the writer and the reader
inline constexpr size_t kPredictedDirectoryEntryBytes = 24;
inline constexpr uint8_t kPaletteCoding = 0, kPredictedCoding = 1, kContextCoding = 2, kPlacedContextCoding = 3, kPlacedLabelCoding = 4,
                         kRescaledFloatCoding = 5, kSpatialContextCoding = 6, kSpatialLabelCoding = 7, kFloatCoding = 8, kFloatVectorCoding = 9,
                         kFittedContextCoding = 10, kFittedRescaledFloatCoding = 11, kFloatIntegerCoding = 12, kWideContextCoding = 13,
                         kWideRescaledFloatCoding = 14, kBandedContextCoding = 15, kBandedRescaledFloatCoding = 16, kShapedLabelCoding = 17,
                         kTiledLabelCoding = 18, kTiledContextCoding = 19, kTiledRescaledFloatCoding = 20,
                         kReferencedContextCoding = 21, kReferencedRescaledFloatCoding = 22, kCodingCount = 23;
// Entries of a brick instance of the attribute layout (a solid node: 1).
inline uint64_t layoutEntries(uint64_t mask) { return mask ? uint64_t(std::popcount(mask)) : 1; }
} // namespace detail

// A channel of float32 or vec3s entries (an integer channel has none):
// their bits are predicted (coding 8; vec3s: each component, coding 9), and
// with a lattice (float32) its integers tried too (coding 5).
struct FloatChannel {
    std::optional<ValueRescale> lattice;  // the rescale the entries are believed to lie on
};

class PredictedWindowWriter {
public:
    // As ValueWindowWriter's (`valueSize` 4 or 8). With `floats`, the
    // entries are float32 (valueSize 4) and need places.
    explicit PredictedWindowWriter(uint32_t valueSize, unsigned parallel = 0, const std::string& spillNear = "", uint64_t spillInMemory = 0,
                                   std::optional<FloatChannel> floats = std::nullopt);
    // `values`: the entries of the brick instances `layout` describes (per
    // instance in attribute order its stored mask, 0 for a solid node),
    // continuing the previous call; `places`: where each lies
    // (encoding::attributePlaces), for an int32 channel whose windows are
    // then coded with neighbours across bricks (coding 3). Give them in
    // every call or in none.
    void add(std::span<const uint8_t> values, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places = {});
    // As ValueWindowWriter's.
    void trackRange(ValueType type) { rangeType_ = type; }
    ValueWindowsPayload finish();  // its `predicted` is set
    uint64_t entries() const { return entries_; }
    // Share mode and assembly, as ValueWindowWriter's (the loose parts
    // carry their bricks' layout).
    void beginShare(uint64_t firstEntry, bool endsLayer);
    ShareWindows finishShare();
    void addCoded(uint64_t window, const ShareWindows::Coded& coded, std::span<const uint8_t> bytes);
    void addShare(const ShareWindows& share);

private:
    struct Window {
        std::vector<uint8_t> values;
        std::vector<uint64_t> layout;
        std::vector<coding::BrickPlace> places;
        uint64_t entries = 0;
    };
    void codePending();
    uint32_t valueSize_;
    uint64_t windowEntries_;  // E, above
    std::optional<FloatChannel> floats_;
    unsigned parallel_;
    uint64_t entries_ = 0, windows_ = 0;
    std::vector<Window> pending_;  // full windows not yet coded, and the one filling (last)
    std::vector<uint8_t> payload_;
    std::shared_ptr<ScratchFile> spill_;
    struct Directory { uint64_t stored, raw, entries; };
    std::vector<Directory> directory_;
    bool share_ = false, endsLayer_ = true;
    std::optional<bool> placed_;  // whether the calls so far gave places
    uint64_t headEnd_ = 0;
    ShareWindows::Loose head_;
    std::optional<ValueType> rangeType_;
    ValueRange range_;
};

// A series' reference (codings 21 and 22; FORMAT.md 8.6): a layer whose
// grid's DAG is an earlier grid's, entry for entry, may code a window with
// that grid's same window (the same entries: a 4-D scan's previous volume)
// as four more neighbours of each voxel (coding/IntVolumeCoder.h's
// IntCoderOptions::reference). Window k then needs the reference's window
// k decoded first, and that one its own reference's: `next`.
//
// So that a decode of a whole series in order decodes each window once and
// holds at most a volume's windows more: a decode of the reference grid's
// own window k offers it (`offer`, ValueWindowsPayload::referencedBy), and
// the grid that refers to it takes it from there (`window`: an offered
// window is handed out once, then forgotten). A window not offered is
// decoded again from the payload (and its own chain).
// A reader refuses a chain longer than kMaxReferenceChain grids (the
// decode of a window recurses along it; the encoder's key grids keep it
// shorter: --key-every at most 256).
inline constexpr unsigned kMaxReferenceChain = 255;
struct WindowReference {
    std::vector<uint8_t> payload;                 // the earlier grid's PredictedWindows payload
    WindowDirectory directory;                    // its directory (the same windows as the layer's)
    std::shared_ptr<const WindowReference> next;  // its own reference, or null
    unsigned depth = 1;                           // the grids of the chain: 1 + next's
    std::string what;                             // names it in errors
    // Window k's entries (as decodePredictedWindow gives them): the one
    // offered, or decoded.
    std::vector<uint8_t> window(size_t k, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places) const;
    // The reference grid's own decode of its window k hands it on.
    void offer(size_t k, std::span<const uint8_t> values) const;
    WindowReference() = default;
    WindowReference(std::vector<uint8_t> bytes, uint32_t valueSize, std::span<const uint64_t> layout, std::shared_ptr<const WindowReference> next,
                    std::string what);

private:
    mutable std::mutex mutex_;
    mutable std::vector<std::vector<uint8_t>> offered_;
};
// Whether two directories over one layout cut it into the same windows
// (the same entries in each), as a referring grid's and its reference's must.
inline bool sameWindowCuts(const WindowDirectory& a, const WindowDirectory& b) {
    if (a.windows.size() != b.windows.size()) return false;
    for (size_t k = 0; k < a.windows.size(); ++k)
        if (a.windows[k].entries != b.windows[k].entries) return false;
    return true;
}
// The entries of the reference's window k, asked for only by the windows
// whose coding reads it.
using ReferenceWindow = std::function<std::vector<uint8_t>(size_t window)>;
// The windows of a layer decoded whole (`entries` in attribute order, cut
// as `dir` says; both must outlive the function).
inline ReferenceWindow windowsOf(const std::vector<uint8_t>& entries, const WindowDirectory& dir) {
    return [&entries, &dir](size_t k) {
        const WindowDirectory::Window& e = dir.windows.at(k);
        const uint64_t vs = dir.valueSize;
        return std::vector<uint8_t>(entries.begin() + ptrdiff_t(e.firstEntry * vs), entries.begin() + ptrdiff_t((e.firstEntry + e.entries) * vs));
    };
}
// `reference`'s window, over the layer's `layout` and `places` (which must
// outlive the function); an empty function for a null reference.
ReferenceWindow referenceWindows(const std::shared_ptr<const WindowReference>& reference, std::span<const uint64_t> layout,
                                 std::span<const coding::BrickPlace> places);

// How many windows use each coding (index: the coding byte, 0..9), read
// from each window's first byte only (a compressed window's start is
// inflated, nothing more); the directory is checked as for decoding. And
// what each coding is, in a few words (a report's names).
std::vector<uint64_t> predictedWindowCodings(std::span<const uint8_t> payload, uint32_t valueSize, std::span<const uint64_t> layout,
                                             const std::string& what);
// The same from a payload of `payloadBytes` read in parts (`read(offset,
// n)`: its header, its directory and each window's first byte; a
// compressed window whole), without the DAG: the directory is checked
// against the payload's size, not the layout (what `info` reads of a file
// whose Summary section tells the rest).
using PayloadPart = std::function<std::vector<uint8_t>(uint64_t offset, uint64_t n)>;
std::vector<uint64_t> predictedWindowCodings(uint64_t payloadBytes, const PayloadPart& read, uint32_t valueSize, const std::string& what);
const char* predictedCodingName(uint8_t coding);

// Coding 9's payload: vec3s entries (12 bytes each) over `layout`/`places`,
// coding::encodePlacedFloatVectors' bytes (each component predicted, the
// later ones under cross-component contexts); and its inverse, which
// validates it (throws vdbdag::Error starting with `what`).
std::vector<uint8_t> encodeFloatVectors(std::span<const uint8_t> values, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places);
std::vector<uint8_t> decodeFloatVectors(std::span<const uint8_t> payload, std::span<const uint64_t> layout, uint64_t entries,
                                        std::span<const coding::BrickPlace> places, const std::string& what);

// All at once.
std::vector<uint8_t> encodePredictedWindows(std::span<const uint8_t> values, uint32_t valueSize, std::span<const uint64_t> layout,
                                            std::span<const coding::BrickPlace> places = {}, std::optional<FloatChannel> floats = std::nullopt);

// The entries in attribute order; validates the payload against `layout`
// (the DAG's attributeLayout) and throws vdbdag::Error starting with `what`.
// `places` (encoding::attributePlaces) are needed by codings 3-8. The
// windows are decoded through `parallel` when given.
// `reference`: the entries of the reference's windows (codings 21, 22),
// which a window of either coding without it refuses; `offerTo`: the
// reference of the grid that refers to this one (its referencedBy), which
// each decoded window is offered to.
std::vector<uint8_t> decodePredictedWindows(std::span<const uint8_t> payload, uint32_t valueSize, std::span<const uint64_t> layout,
                                            const std::string& what, std::span<const coding::BrickPlace> places, const ParallelFor& parallel = {},
                                            const ReferenceWindow& reference = {}, const WindowReference* offerTo = nullptr);

// Window by window (WindowCursor.h): the directory, checked against
// `layout` as decodePredictedWindows checks it, and window k's entries.
WindowDirectory readPredictedWindowDirectory(std::span<const uint8_t> payload, uint32_t valueSize, std::span<const uint64_t> layout,
                                             const std::string& what);
std::vector<uint8_t> decodePredictedWindow(std::span<const uint8_t> payload, const WindowDirectory& dir, size_t k, std::span<const uint64_t> layout,
                                           const std::string& what, std::span<const coding::BrickPlace> places, const ReferenceWindow& reference = {});

// A series' reference chosen for a layer's windows (the encoder's pass,
// pipeline/SeriesReference.h): each window of coding 15, 16, 19 or 20
// (`payload`'s windows need no reference; `own(k)`, window k's entries as
// they decode) coded again with `reference(k)`, the reference grid's
// window k (a grid of the same DAG), as its reference (codings 21 and 22),
// kept where that is smaller. Returns the new payload, or nothing when no
// window gained; `referenced` counts the windows that did.
std::optional<std::vector<uint8_t>> referencePredictedWindows(std::span<const uint8_t> payload, const ReferenceWindow& own, const ReferenceWindow& reference,
                                                              uint32_t valueSize, std::span<const uint64_t> layout, std::span<const coding::BrickPlace> places,
                                                              const std::string& what, uint64_t& referenced);

} // namespace vdbdag::attributes
