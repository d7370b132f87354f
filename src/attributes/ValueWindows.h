// A value channel at rest in fixed windows: the entries, in attribute
// order, cut into windows of kValueWindowEntries entries (the last one
// shorter); each window palette-compressed on its own (compressPalette, its
// own material array) and zstd-compressed on its own. So an encoder holds one
// window (per core) at a time, never the whole channel, whatever the grid's
// size; windows are coded in parallel; and the bytes do not depend on how
// the entries arrived (all at once or cube by cube), the memory limit or the
// thread count, because the windows are cut at fixed entry counts.
//
// Payload of a ValueWindows / InactiveValueWindows section (the container
// stores it as it is: its frames are compressed already):
//   u32 value size, u64 entries, u64 window entries (a power of two),
//   u64 window count W = ceil(entries / window entries),
//   the W windows back to back,
//   W x (u64 stored bytes, u64 raw bytes), the directory, last (a writer
//     appends each window as soon as it is coded): raw == stored: the
//     window is its serializePalette bytes as they are; else one zstd frame
//     of them that declares the raw size and carries zstd's checksum.
// A reader (decodeValueWindows) merges the windows into one traceable
// PaletteChannel: their material arrays and palettes concatenated, and each
// window's whole-material-array blocks turned into palette blocks over its
// own part of the merged material array.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "src/coding/BrickValueCoder.h"

#include "src/attributes/PaletteChannel.h"
#include "src/attributes/ValueRange.h"
#include "src/util/ScratchFile.h"

namespace vdbdag::attributes {

// Runs body(0) .. body(n - 1), in any order and on any threads: how a
// decoder of windows may spread them (the core library passes TBB's
// parallel_for, util/ParallelFor.h; the reader library, which links no
// thread pool, none: one after another).
using ParallelFor = std::function<void(size_t n, const std::function<void(size_t)>& body)>;

inline constexpr uint64_t kValueWindowEntries = uint64_t(1) << 22;

// A coded payload, in memory or (an encoder in bounded memory) the whole of
// a scratch file.
struct WindowReference;  // PredictedWindows.h

struct ValueWindowsPayload {
    std::vector<uint8_t> bytes;
    // A predicted payload whose windows may read those of an earlier grid
    // of the file (codings 21, 22; section ValueReference, FORMAT.md 8.6):
    // how many grids back it is (0: none), and, in a scene read from a
    // file, its windows (set by the reader).
    uint32_t referenceDistance = 0;
    std::shared_ptr<const WindowReference> reference;
    // The reference of the grid that refers to this one, if read: each
    // window decoded in order is offered to it (WindowReference::offer).
    std::shared_ptr<const WindowReference> referencedBy;
    // The range of the values coded, when the writer was asked to keep it
    // (trackRange): an encoder's Summary section (docs/FORMAT.md 10.1).
    std::optional<ValueRange> range;
    std::shared_ptr<const ScratchFile> file;
    // An integer channel's PredictedWindows payload (PredictedWindows.h),
    // not a ValueWindows one.
    bool predicted = false;
    bool empty() const { return bytes.empty() && !file; }
    uint64_t size() const { return file ? file->size() : bytes.size(); }
    std::vector<uint8_t> load() const;  // the bytes, read back when spilled
};

// One process's share of a layer (several processes, pipeline/CubeTeam.h):
// the windows wholly inside it, coded, and the entries of the windows it
// shares with its neighbours (the head before its first window, the tail
// after its last), raw, for process 0 to complete. Any process codes a
// window to the same bytes, so the file does not depend on the split.
struct ShareWindows {
    uint64_t firstWindow = 0;  // index of the first coded window
    struct Coded {
        uint64_t stored = 0, raw = 0, entries = 0;
    };
    std::vector<Coded> directory;  // per coded window
    std::vector<uint8_t> coded;    // the coded windows back to back
    struct Loose {
        uint64_t window = 0;            // the window they belong to
        std::vector<uint8_t> values;    // entries
        std::vector<uint64_t> layout;   // their brick instances (predicted windows)
        std::vector<coding::BrickPlace> places;  // and where they lie (int32 predicted windows)
        bool empty() const { return values.empty(); }
    };
    Loose head, tail;
    std::optional<ValueRange> range;  // of every value this share was given (trackRange)
    std::vector<uint8_t> serialize() const;
    static ShareWindows deserialize(std::span<const uint8_t> bytes);
};

// Takes the entries in order (any number per call) and codes every full
// window; at most `parallel` windows (0: one per core) wait to be coded
// together, so memory holds about that many windows.
class ValueWindowWriter {
public:
    // `expectedEntries`: how many entries will come, if known; the payload's
    // memory is then reserved once (untouched reserve costs no resident
    // memory), so it is never copied while it grows.
    // With `spillNear`, coded windows go to scratch space (the first
    // `spillInMemory` bytes in memory, the rest in a file in that path's
    // folder: ScratchFile.h).
    explicit ValueWindowWriter(uint32_t valueSize, uint64_t expectedEntries = 0, unsigned parallel = 0, const std::string& spillNear = "",
                               uint64_t spillInMemory = 0);
    void add(std::span<const uint8_t> values);
    // Keep the range of the values added (and of the shares added) as
    // values of `type`: finish() and finishShare() return it.
    void trackRange(ValueType type) { rangeType_ = type; }
    // The section payload. The writer is spent afterwards.
    ValueWindowsPayload finish();
    // Share mode (before the first add): the entries start at `firstEntry`
    // of the layer and end it when `endsLayer`; finishShare() instead of
    // finish(). (No spilling in share mode.)
    void beginShare(uint64_t firstEntry, bool endsLayer);
    ShareWindows finishShare();
    // On the writer that assembles the shares: a window another process
    // coded, in its place (`entries()` must be where it starts).
    void addCoded(uint64_t window, const ShareWindows::Coded& coded, std::span<const uint8_t> bytes);
    // ... and a whole share: its head, coded windows and tail, in order.
    void addShare(const ShareWindows& share);
    // A fast-zstd estimate of the payload (the sum of the windows'
    // zstd level-1 sizes), the yardstick GridCodec compares other codings
    // with; valid after finish().
    uint64_t estimate() const { return estimate_; }
    uint64_t entries() const { return entries_; }

private:
    void codePending();
    uint32_t valueSize_;
    unsigned parallel_;
    uint64_t entries_ = 0, estimate_ = 0;
    std::vector<std::vector<uint8_t>> pending_;  // full windows not yet coded, and the one filling (last)
    std::vector<uint8_t> payload_;               // header placeholder, then the coded windows
    std::shared_ptr<ScratchFile> spill_;         // ... or there
    std::vector<std::pair<uint64_t, uint64_t>> directory_;  // stored, raw bytes per window
    bool share_ = false, endsLayer_ = true;
    uint64_t headEnd_ = 0;  // share mode: the first window boundary at or after the first entry
    ShareWindows::Loose head_;
    std::vector<uint64_t> codedEntries_;  // entries per coded window
    std::optional<ValueType> rangeType_;
    ValueRange range_;
};

// For the window writers (this one and PredictedWindows.h): a coded window
// appended to the payload in memory or in the scratch file, and the
// payload sealed: the header over its placeholder at the start, the
// directory at the end.
void appendWindow(std::vector<uint8_t>& payload, ScratchFile* spill, std::span<const uint8_t> bytes);
ValueWindowsPayload sealWindows(std::vector<uint8_t>&& payload, std::shared_ptr<ScratchFile>&& spill, std::span<const uint8_t> header,
                                std::span<const uint8_t> directory);

// All of `values` at once.
std::vector<uint8_t> encodeValueWindows(std::span<const uint8_t> values, uint32_t valueSize, uint64_t* estimate = nullptr);

// Validates the payload (sizes, frames, every window's palette channel) and
// merges it; throws vdbdag::Error starting with `what`.
PaletteChannel decodeValueWindows(std::span<const uint8_t> payload, const std::string& what);

// Window by window (a reader that streams, WindowCursor.h): the header and
// directory, checked as decodeValueWindows checks them.
struct WindowDirectory {
    uint32_t valueSize = 0;
    uint64_t entries = 0;
    struct Window {
        uint64_t offset = 0, stored = 0, raw = 0;  // in the payload
        uint64_t firstEntry = 0, entries = 0;
        uint64_t firstBrick = 0, bricks = 0;  // PredictedWindows: its part of the layout
    };
    std::vector<Window> windows;
};
WindowDirectory readValueWindowDirectory(std::span<const uint8_t> payload, const std::string& what);
// Window k's channel (its entries numbered from 0), checked.
PaletteChannel decodeValueWindow(std::span<const uint8_t> payload, const WindowDirectory& dir, size_t k, const std::string& what);
// A window's raw bytes (inflated when stored as a frame).
std::vector<uint8_t> windowRawBytes(std::span<const uint8_t> payload, const WindowDirectory::Window& w, const std::string& what);

} // namespace vdbdag::attributes
