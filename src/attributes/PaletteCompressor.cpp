// Palette compression of an attribute array (Dado et al. §4.2, Alg. 1),
// in O(n log n):
//  0. every entry gets the dense id of its distinct value (hash map, with a
//     shortcut for runs of equal values);
//  1. phase one, for ω = 0..3: the largest blocks with at most 2^ω distinct
//     values. Instead of the paper's literal "largest block" scan, which is
//     quadratic, a sliding window gives every maximal window in O(n); the
//     windows go into a max-heap by length and are accepted largest first,
//     clipped lazily to the still-free gap they start in (a clipped window is
//     pushed back with its new length). The window scan runs in parallel over
//     fixed chunks of starts, with the same windows as a sequential scan. A block is accepted when it pays:
//     len * ω + palette + directory < len * (ω + 1) (the paper's line 6), and
//     it beats direct storage;
//  2. phase two: the rest is cut left to right; from each start, the longest
//     block for each ω = 0..8 and a direct block are costed per entry and the
//     cheapest is taken. The gaps phase one left are cut in parallel (TBB),
//     which cannot change the result: the output is byte-identical for any
//     thread count.
// Costs include each value's share of the material array (its bits divided
// by its number of occurrences), so unique floats fall back to direct
// storage and a channel never grows by more than its directory.
#include "src/attributes/PaletteCompressor.h"


#include <algorithm>
#include <bit>
#include <cstring>
#include <map>
#include <unordered_map>
#include <queue>
#include <set>
#include <cstdlib>
#include <sys/mman.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <xxhash.h>

#include "src/format/ByteIO.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {
namespace {

constexpr double kDirectoryBits = 8 * 21;  // firstEntry, dataOffset, paletteOffset, ω
constexpr double kPaletteEntryBits = 32;   // palettes store u32 material indices
constexpr uint64_t kMaxBlockEntries = 1u << 14;

struct Segment {
    uint64_t start, length;
    uint8_t omega;  // PaletteBlock::kDirect for direct storage, kWhole for material-array indices
};
constexpr uint8_t kWhole = 0xFE;

// Bitwise equality and hash of one value, specialised for the common sizes
// (a libc memcmp call per 4-byte value costs more than the comparison).
inline bool sameValue(const uint8_t* a, const uint8_t* b, uint32_t vs) {
    switch (vs) {
        case 4: { uint32_t x, y; std::memcpy(&x, a, 4); std::memcpy(&y, b, 4); return x == y; }
        case 8: { uint64_t x, y; std::memcpy(&x, a, 8); std::memcpy(&y, b, 8); return x == y; }
        case 12: { uint64_t x, y; uint32_t z, w; std::memcpy(&x, a, 8); std::memcpy(&y, b, 8); std::memcpy(&z, a + 8, 4); std::memcpy(&w, b + 8, 4); return x == y && z == w; }
        default: return std::memcmp(a, b, vs) == 0;
    }
}
inline uint64_t hashValue(const uint8_t* v, uint32_t vs) {
    if (vs == 4 || vs == 8) {
        uint64_t x = 0;
        std::memcpy(&x, v, vs);
        x ^= x >> 31; x *= 0x7fb5d329728ea185ull; x ^= x >> 27; x *= 0x81dadef4bc2dd44dull; x ^= x >> 33;
        return x;
    }
    return XXH3_64bits(v, vs);
}

// A zero-initialised array for random access over hundreds of MB: backed by
// transparent huge pages where the kernel allows (madvise mode), which
// removes most TLB misses of the hash table below.
template <typename T>
class RandomAccessArray {
public:
    explicit RandomAccessArray(size_t count) : count_(count) {
        bytes_ = (count * sizeof(T) + kHuge - 1) / kHuge * kHuge;
        data_ = static_cast<T*>(std::aligned_alloc(kHuge, bytes_));
        if (!data_) throw std::bad_alloc();
        madvise(data_, bytes_, MADV_HUGEPAGE);
        std::memset(static_cast<void*>(data_), 0, bytes_);
    }
    ~RandomAccessArray() { std::free(data_); }
    RandomAccessArray(const RandomAccessArray&) = delete;
    RandomAccessArray& operator=(const RandomAccessArray&) = delete;
    RandomAccessArray(RandomAccessArray&& o) noexcept : data_(o.data_), count_(o.count_), bytes_(o.bytes_) { o.data_ = nullptr; }
    RandomAccessArray& operator=(RandomAccessArray&& o) noexcept {
        std::swap(data_, o.data_);
        std::swap(count_, o.count_);
        std::swap(bytes_, o.bytes_);
        return *this;
    }
    T& operator[](size_t i) { return data_[i]; }
    const T& operator[](size_t i) const { return data_[i]; }
    size_t size() const { return count_; }

private:
    static constexpr size_t kHuge = size_t(2) << 20;
    T* data_ = nullptr;
    size_t count_ = 0, bytes_ = 0;
};

// Doubles an open-addressing table of slots (id1 == 0: empty), placing each
// slot at bucketOf(slot, new mask) with linear probing.
template <typename Slot, typename Bucket>
void growTable(RandomAccessArray<Slot>& slots, size_t& mask, Bucket&& bucketOf) {
    RandomAccessArray<Slot> bigger(slots.size() * 2);
    const size_t m = bigger.size() - 1;
    for (size_t k = 0; k < slots.size(); ++k) {
        const Slot s = slots[k];
        if (!s.id1) continue;
        size_t h = bucketOf(s, m);
        while (bigger[h].id1) h = (h + 1) & m;
        bigger[h] = s;
    }
    slots = std::move(bigger);
    mask = m;
}

// Dense ids of the distinct values, in order of first occurrence, for
// values of 4 or 8 bytes: each slot holds the value's bits beside its id, so
// a probe is one load (no detour through the value array) and growth never
// rereads values.
template <typename Key>
std::vector<uint32_t> distinctKeyIds(const uint8_t* values, uint64_t n, std::vector<uint64_t>& firstOccurrence) {
    struct Slot {
        Key key;
        uint32_t id1;  // id + 1, 0 = empty
    };
    auto bucketOf = [](Key k, size_t mask) {
        uint64_t x = uint64_t(k);
        x ^= x >> 31; x *= 0x7fb5d329728ea185ull; x ^= x >> 27;
        return size_t(x >> 17) & mask;
    };
    std::vector<uint32_t> ids(n);
    firstOccurrence.reserve(size_t(std::min<uint64_t>(n, uint64_t(1) << 32)));
    RandomAccessArray<Slot> slots(size_t(1) << 16);
    size_t mask = slots.size() - 1;
    auto grow = [&]() { growTable(slots, mask, [&](const Slot& s, size_t m) { return bucketOf(s.key, m); }); };
    Key previous{};
    for (uint64_t i = 0; i < n; ++i) {
        Key k;
        std::memcpy(&k, values + i * sizeof(Key), sizeof(Key));
        if (i > 0 && k == previous) { ids[i] = ids[i - 1]; continue; }
        previous = k;
        for (size_t h = bucketOf(k, mask);; h = (h + 1) & mask) {
            const Slot slot = slots[h];
            if (slot.id1 == 0) {
                if (firstOccurrence.size() >= 0xFFFFFFF0u) throw Error("more than 2^32 distinct values in one channel");
                firstOccurrence.push_back(i);
                slots[h] = Slot{k, uint32_t(firstOccurrence.size())};
                ids[i] = uint32_t(firstOccurrence.size() - 1);
                if (firstOccurrence.size() * 2 > slots.size()) {
                    if (slots.size() >= (size_t(1) << 32)) throw Error("too many distinct values in one channel");
                    grow();
                }
                break;
            }
            if (slot.key == k) { ids[i] = slot.id1 - 1; break; }
        }
    }
    return ids;
}

// Dense ids of the distinct values of any size, in order of first
// occurrence. The table keeps each slot's 32-bit hash next to its id, so a
// probe touches the value array only on a hash match.
std::vector<uint32_t> distinctIds(std::span<const uint8_t> values, uint32_t vs, uint64_t n, std::vector<uint64_t>& firstOccurrence) {
    if (vs == 4) return distinctKeyIds<uint32_t>(values.data(), n, firstOccurrence);
    if (vs == 8) return distinctKeyIds<uint64_t>(values.data(), n, firstOccurrence);
    struct Slot {
        uint32_t id1;   // id + 1, 0 = empty
        uint32_t hash;  // low 32 bits of the value's hash (also its bucket)
    };
    std::vector<uint32_t> ids(n);
    // Reserved, not touched: growth never copies (and never holds the old
    // and the new array at once); only the pages used become resident.
    firstOccurrence.reserve(size_t(std::min<uint64_t>(n, uint64_t(1) << 32)));
    RandomAccessArray<Slot> slots(size_t(1) << 16);
    size_t mask = slots.size() - 1;
    auto grow = [&]() { growTable(slots, mask, [](const Slot& s, size_t m) { return size_t(s.hash) & m; }); };
    for (uint64_t i = 0; i < n; ++i) {
        const uint8_t* v = values.data() + i * vs;
        if (i > 0 && sameValue(v, v - vs, vs)) { ids[i] = ids[i - 1]; continue; }
        const uint32_t hash = uint32_t(hashValue(v, vs));
        for (size_t h = hash & mask;; h = (h + 1) & mask) {
            const Slot slot = slots[h];
            if (slot.id1 == 0) {
                if (firstOccurrence.size() >= 0xFFFFFFF0u) throw Error("more than 2^32 distinct values in one channel");
                firstOccurrence.push_back(i);
                slots[h] = Slot{uint32_t(firstOccurrence.size()), hash};
                ids[i] = uint32_t(firstOccurrence.size() - 1);
                if (firstOccurrence.size() * 2 > slots.size()) {
                    if (slots.size() >= (size_t(1) << 32)) throw Error("too many distinct values in one channel");
                    grow();
                }
                break;
            }
            if (slot.hash == hash && sameValue(values.data() + firstOccurrence[slot.id1 - 1] * vs, v, vs)) { ids[i] = slot.id1 - 1; break; }
        }
    }
    return ids;
}

class Partitioner {
public:
    Partitioner(const std::vector<uint32_t>& ids, uint64_t distinct, uint32_t vs)
        : ids_(ids), n_(ids.size()), vs_(vs), materialBits_(std::max(1, int(std::bit_width(distinct > 1 ? distinct - 1 : 1)))),
          distinct_(distinct), share_(distinct, 0.0) {
        std::vector<uint64_t> freq(distinct, 0);
        for (uint32_t id : ids) ++freq[id];
        for (size_t d = 0; d < distinct; ++d) share_[d] = 8.0 * vs / double(freq[d]);
    }

    std::vector<Segment> run() {
        // Phase one for ω = 1..3 accepts only windows longer than
        // minLength(ω): a quick check skips the scans that cannot find one
        // (most of them on noisy values), with the same result.
        for (uint8_t omega = 0; omega < 4; ++omega)
            if (omega == 0 || mayHaveWindow(omega)) phaseOne(omega);
        // Phase two on every gap left. Gaps are independent, so they run in
        // parallel, each thread with its own stamp array; the result is put
        // together in gap order, so it is the same for any thread count.
        std::vector<Segment> segments(accepted_.begin(), accepted_.end());
        std::sort(segments.begin(), segments.end(), [](const Segment& a, const Segment& b) { return a.start < b.start; });
        std::vector<std::pair<uint64_t, uint64_t>> gaps;
        uint64_t at = 0;
        for (const Segment& s : segments) {
            gaps.push_back({at, s.start});
            at = s.start + s.length;
        }
        gaps.push_back({at, n_});
        std::vector<std::vector<Segment>> perGap(gaps.size());
        tbb::enumerable_thread_specific<Stamps> stamps([&] { return Stamps(distinct_); });
        tbb::parallel_for(tbb::blocked_range<size_t>(0, gaps.size()), [&](const tbb::blocked_range<size_t>& range) {
            Stamps& local = stamps.local();
            for (size_t g = range.begin(); g != range.end(); ++g) phaseTwo(gaps[g].first, gaps[g].second, local, perGap[g]);
        });
        std::vector<Segment> all;
        for (size_t g = 0; g < gaps.size(); ++g) {
            all.insert(all.end(), perGap[g].begin(), perGap[g].end());
            if (g < segments.size()) all.push_back(segments[g]);
        }
        // Merge neighbouring direct blocks (one directory entry instead of many).
        std::vector<Segment> merged;
        for (const Segment& s : all) {
            if (!merged.empty() && s.omega == PaletteBlock::kDirect && merged.back().omega == PaletteBlock::kDirect &&
                merged.back().length + s.length <= (uint64_t(1) << 30))
                merged.back().length += s.length;
            else
                merged.push_back(s);
        }
        return merged;
    }

private:
    struct SegmentLess {
        bool operator()(const Segment& a, const Segment& b) const { return a.start < b.start; }
    };

    // End of the free gap containing `start` (or start itself if covered).
    std::pair<bool, uint64_t> freeGapEnd(uint64_t start) const {
        auto next = accepted_.lower_bound(Segment{start + 1, 0, 0});
        if (next != accepted_.begin()) {
            auto prev = std::prev(next);
            if (prev->start + prev->length > start) return {false, start};
        }
        return {true, next == accepted_.end() ? n_ : next->start};
    }

    double materialShare(uint64_t begin, uint64_t end) const {
        double s = 0;
        for (uint64_t i = begin; i < end; ++i) s += share_[ids_[i]];
        return s;
    }

    bool paletteWins(uint64_t begin, uint64_t length, uint8_t omega) const {
        const double paletteBits = double(length) * omega + double(uint64_t(1) << omega) * kPaletteEntryBits + kDirectoryBits;
        if (!(paletteBits < double(length) * (omega + 1))) return false;                  // Alg. 1, line 6
        return paletteBits + materialShare(begin, begin + length) < double(length) * 8.0 * vs_ + kDirectoryBits;  // beats direct
    }

    // The shortest window phase one considers for ω.
    static double minLength(uint8_t omega) { return double(uint64_t(1) << omega) * kPaletteEntryBits + kDirectoryBits; }

    // False when no window longer than minLength(ω) has at most 2^ω
    // distinct ids: such a window (length >= T + 1, T = minLength) holds a
    // whole aligned block of B = floor((T + 2) / 2) entries, which has at
    // most 2^ω distinct ids too. Each block is read until it shows more, so
    // on noisy values this costs a few entries per block.
    bool mayHaveWindow(uint8_t omega) const {
        const uint64_t limit = uint64_t(1) << omega;
        const uint64_t block = (uint64_t(minLength(omega)) + 2) / 2;
        uint32_t seen[9];
        for (uint64_t begin = 0; begin + block <= n_; begin += block) {
            uint64_t distinct = 0, i = begin;
            for (; i < begin + block; ++i) {
                const uint32_t id = ids_[i];
                if (std::find(seen, seen + distinct, id) != seen + distinct) continue;
                if (distinct == limit) break;
                seen[distinct++] = id;
            }
            if (i == begin + block) return true;
        }
        return false;
    }

    void phaseOne(uint8_t omega) {
        const uint64_t limit = uint64_t(1) << omega;
        const double minLength = Partitioner::minLength(omega);
        // Maximal windows with <= 2^omega distinct ids, inside each free gap,
        // by a sliding window. The gaps are cut into fixed chunks of window
        // starts scanned in parallel (each chunk restarts its window at its
        // first start); a chunk's first window is kept only if it is not
        // inside the previous start's window, exactly as a sequential scan
        // decides, so the windows do not depend on the thread count.
        struct Chunk {
            uint64_t begin, end, gapEnd;
            uint64_t lastRight = 0;  // right end of the window of start end-1
            std::vector<std::pair<uint64_t, uint64_t>> windows;  // (length, start)
        };
        std::vector<Chunk> chunks;
        auto addGap = [&](uint64_t begin, uint64_t end) {
            for (uint64_t a = begin; a < end; a += kScanChunk) chunks.push_back(Chunk{a, std::min(end, a + kScanChunk), end, 0, {}});
        };
        uint64_t gapStart = 0;
        for (const Segment& s : accepted_) {
            if (s.start > gapStart) addGap(gapStart, s.start);
            gapStart = s.start + s.length;
        }
        if (gapStart < n_) addGap(gapStart, n_);
        tbb::enumerable_thread_specific<WindowCounts> scratch([&] { return WindowCounts(distinct_); });
        tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks.size()), [&](const tbb::blocked_range<size_t>& range) {
            WindowCounts& w = scratch.local();
            for (size_t c = range.begin(); c != range.end(); ++c) {
                Chunk& chunk = chunks[c];
                if (omega == 0) {
                    // One distinct value: the maximal windows are the runs of
                    // equal ids, found without the window counts.
                    uint64_t lastRight = chunk.begin;
                    for (uint64_t left = chunk.begin; left < chunk.end;) {
                        uint64_t right = left + 1;
                        while (right < chunk.gapEnd && ids_[right] == ids_[left]) ++right;
                        if (right > lastRight && double(right - left) > minLength) chunk.windows.push_back({right - left, left});
                        lastRight = right;
                        left = right;
                    }
                    chunk.lastRight = lastRight;
                    continue;
                }
                ++w.epoch;
                uint64_t distinct = 0, right = chunk.begin, lastRight = chunk.begin;
                for (uint64_t left = chunk.begin; left < chunk.end; ++left) {
                    while (right < chunk.gapEnd) {
                        const uint32_t id = ids_[right];
                        const bool fresh = w.stamp[id] != w.epoch || w.count[id] == 0;
                        if (fresh && distinct == limit) break;
                        if (w.stamp[id] != w.epoch) { w.stamp[id] = w.epoch; w.count[id] = 0; }
                        if (w.count[id]++ == 0) ++distinct;
                        ++right;
                    }
                    if (right > lastRight && double(right - left) > minLength) chunk.windows.push_back({right - left, left});
                    lastRight = std::max(lastRight, right);
                    const uint32_t id = ids_[left];
                    if (--w.count[id] == 0) --distinct;
                }
                chunk.lastRight = lastRight;
            }
        });
        std::vector<std::pair<uint64_t, uint64_t>> windows;
        for (size_t c = 0; c < chunks.size(); ++c) {
            const Chunk& chunk = chunks[c];
            size_t from = 0;
            const bool continuesGap = c > 0 && chunks[c - 1].end == chunk.begin && chunks[c - 1].gapEnd == chunk.gapEnd;
            if (continuesGap && !chunk.windows.empty() && chunk.windows[0].second == chunk.begin &&
                chunk.begin + chunk.windows[0].first <= chunks[c - 1].lastRight)
                from = 1;  // inside the window of the previous start: not maximal
            windows.insert(windows.end(), chunk.windows.begin() + long(from), chunk.windows.end());
        }
        std::priority_queue<std::pair<uint64_t, uint64_t>> heap(std::less<std::pair<uint64_t, uint64_t>>(), std::move(windows));
        while (!heap.empty()) {
            auto [length, start] = heap.top();
            heap.pop();
            if (double(length) <= minLength) break;  // the heap is ordered: nothing longer remains
            const auto [free, gapEnd] = freeGapEnd(start);
            if (!free) continue;
            if (start + length > gapEnd) {
                heap.push({gapEnd - start, start});
                continue;
            }
            if (paletteWins(start, length, omega)) accepted_.insert(Segment{start, length, omega});
        }
    }

    // Per-thread window counts for phase one (stamp == epoch: count valid).
    struct WindowCounts {
        explicit WindowCounts(size_t distinct) : stamp(distinct, 0), count(distinct, 0) {}
        std::vector<uint32_t> stamp, count;
        uint32_t epoch = 0;
    };
    static constexpr uint64_t kScanChunk = uint64_t(1) << 20;

    // Per-thread "seen in the current scan" marks for phase two.
    struct Stamps {
        explicit Stamps(size_t distinct) : stamp(distinct, 0) {}
        std::vector<uint32_t> stamp;
        uint32_t epoch = 0;
    };

    void phaseTwo(uint64_t begin, uint64_t end, Stamps& marks, std::vector<Segment>& out) const {
        std::vector<uint32_t>& stamp = marks.stamp;
        for (uint64_t start = begin; start < end;) {
            const uint64_t stop = std::min(end, start + kMaxBlockEntries);
            // lengthFor[ω]: longest block from `start` with <= 2^ω distinct ids.
            uint64_t lengthFor[9];
            double shareUpTo[9];
            const uint32_t epoch = ++marks.epoch;
            uint64_t distinct = 0, i = start;
            double share = 0;
            // Palette costs per entry as ω grows. Every later candidate costs
            // strictly more than a floor (ω' bits, materialBits_, 8 valueSize
            // bits, each plus positive overheads), so once the best palette
            // so far is at or below all the floors the scan stops: the choice
            // is the one the full comparison below would make, without
            // scanning up to 257 distinct values from every start.
            auto paletteCost = [&](unsigned omega) {
                const double len = double(lengthFor[omega]);
                return (len * omega + double(uint64_t(1) << omega) * kPaletteEntryBits + kDirectoryBits + shareUpTo[omega]) / len;
            };
            double bestPalette = 0;
            unsigned bestOmega = 0;
            bool settled = false;
            for (unsigned omega = 0; omega <= 8; ++omega) {
                const uint64_t limit = uint64_t(1) << omega;
                for (; i < stop; ++i) {
                    const uint32_t id = ids_[i];
                    if (stamp[id] != epoch) {
                        if (distinct == limit) break;
                        stamp[id] = epoch;
                        ++distinct;
                    }
                    share += share_[id];
                }
                lengthFor[omega] = i - start;
                shareUpTo[omega] = share;
                const double cost = paletteCost(omega);
                if (omega == 0 || cost < bestPalette) { bestPalette = cost; bestOmega = omega; }
                if (omega < 8 && bestPalette <= double(omega + 1) && bestPalette <= double(materialBits_) && bestPalette <= 8.0 * vs_) {
                    settled = true;
                    break;
                }
            }
            if (settled) {
                out.push_back({start, lengthFor[bestOmega], uint8_t(bestOmega)});
                start += lengthFor[bestOmega];
                continue;
            }
            double bestCost = (8.0 * vs_ * double(lengthFor[8]) + kDirectoryBits) / double(lengthFor[8]);
            Segment best{start, lengthFor[8], PaletteBlock::kDirect};
            {   // indices straight into the material array, over the longest block considered; the
                // material share is extrapolated from the scanned prefix (an exact sum would rescan)
                const uint64_t len = stop - start;
                const double share = shareUpTo[8] / double(lengthFor[8]) * double(len);
                const double bits = double(len) * materialBits_ + kDirectoryBits + share;
                if (bits / double(len) < bestCost) { bestCost = bits / double(len); best = {start, len, kWhole}; }
            }
            for (unsigned omega = 0; omega <= 8; ++omega) {
                const double cost = paletteCost(omega);
                if (cost < bestCost) { bestCost = cost; best = {start, lengthFor[omega], uint8_t(omega)}; }
            }
            out.push_back(best);
            start += best.length;
        }
    }

    const std::vector<uint32_t>& ids_;
    uint64_t n_;
    uint32_t vs_;
    int materialBits_;
    size_t distinct_;
    std::vector<double> share_;
    std::set<Segment, SegmentLess> accepted_;
};

// Callers size `words` first (reserveBits), so this stays a few instructions.
inline void putBits(std::vector<uint64_t>& words, uint64_t bitOffset, uint64_t value, unsigned bits) {
    if (bits == 0) return;
    const uint64_t word = bitOffset >> 6;
    const unsigned shift = unsigned(bitOffset & 63);
    words[word] |= value << shift;
    if (shift + bits > 64) words[word + 1] |= value >> (64 - shift);
}
inline void reserveBits(std::vector<uint64_t>& words, uint64_t endBit) {
    const uint64_t need = (endBit >> 6) + 2;
    if (words.size() < need) words.resize(std::max<uint64_t>(need, words.size() + words.size() / 2), 0);
}

// Palettes already stored, found by a hash of their material indices, so
// blocks with the same palette share it (the first one stored wins).
class PaletteTable {
public:
    // Offset of `palette` in `stored`, appending it if it is new.
    uint32_t findOrAdd(const std::vector<uint32_t>& palette, std::vector<uint32_t>& stored) {
        const uint64_t h = XXH3_64bits(palette.data(), palette.size() * sizeof(uint32_t)) ^ palette.size();
        auto [it, end] = offsets_.equal_range(h);
        for (; it != end; ++it) {
            const uint32_t at = it->second.first;
            if (it->second.second == palette.size() && std::equal(palette.begin(), palette.end(), stored.begin() + at)) return at;
        }
        const uint32_t at = uint32_t(stored.size());
        stored.insert(stored.end(), palette.begin(), palette.end());
        offsets_.emplace(h, std::make_pair(at, uint32_t(palette.size())));
        return at;
    }

private:
    std::unordered_multimap<uint64_t, std::pair<uint32_t, uint32_t>> offsets_;  // hash -> (offset, size)
};

// Sorts the distinct ids in `order` by their values read as little-endian
// unsigned integers (the material array's order) and writes those values, in
// that order, to `materials`. Values of up to 4 bytes (float, int32, colour
// and normal codes) are sorted as one uint64 each, key << 32 | id: neither the
// sort nor the copy then reads `first` or the values at random, which was most
// of the cost; wider values through their ids. No two ids share a value, so
// every sort gives the one order.
void sortMaterials(std::vector<uint32_t>& order, const uint8_t* base, const std::vector<uint64_t>& first, uint32_t valueSize,
                   std::vector<uint8_t>& materials) {
    materials.resize(order.size() * valueSize);
    if (valueSize <= 4) {
        std::vector<uint64_t> keyed(order.size());
        for (size_t i = 0; i < order.size(); ++i) {
            const uint8_t* v = base + first[order[i]] * valueSize;
            uint64_t key = 0;
            for (uint32_t b = 0; b < valueSize; ++b) key |= uint64_t(v[b]) << (8 * b);
            keyed[i] = key << 32 | order[i];
        }
        std::sort(keyed.begin(), keyed.end());
        for (size_t i = 0; i < order.size(); ++i) {
            order[i] = uint32_t(keyed[i]);
            for (uint32_t b = 0; b < valueSize; ++b) materials[i * valueSize + b] = uint8_t(keyed[i] >> (32 + 8 * b));
        }
        return;
    }
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        const uint8_t* x = base + first[a] * valueSize;
        const uint8_t* y = base + first[b] * valueSize;
        for (uint32_t k = valueSize; k-- > 0;)
            if (x[k] != y[k]) return x[k] < y[k];
        return false;
    });
    for (size_t i = 0; i < order.size(); ++i) std::memcpy(&materials[i * valueSize], base + first[order[i]] * valueSize, valueSize);
}

} // namespace

PaletteChannel compressPalette(std::span<const uint8_t> values, uint32_t valueSize) {
    PaletteChannel out;
    out.valueSize = valueSize;
    if (valueSize == 0) return out;
    const uint64_t n = values.size() / valueSize;
    out.entryCount = n;
    if (n == 0) return out;
    std::vector<uint64_t> first;
    const std::vector<uint32_t> ids = distinctIds(values, valueSize, n, first);
    const std::vector<Segment> segments = Partitioner(ids, first.size(), valueSize).run();

    // Material indices in value order (the values as little-endian unsigned
    // integers): serializePalette stores the sorted material array as small
    // differences, and neighbouring voxels, which have close values, get
    // close indices.
    std::vector<uint32_t> material(first.size(), UINT32_MAX);  // id -> material index
    {
        std::vector<uint8_t> used(first.size(), 0);
        for (const Segment& s : segments)
            if (s.omega != PaletteBlock::kDirect)
                for (uint64_t i = s.start; i < s.start + s.length; ++i) used[ids[i]] = 1;
        std::vector<uint32_t> order;
        for (uint32_t id = 0; id < used.size(); ++id)
            if (used[id]) order.push_back(id);
        sortMaterials(order, values.data(), first, valueSize, out.materials);
        for (uint32_t m = 0; m < order.size(); ++m) material[order[m]] = m;
    }
    PaletteTable paletteAt;                                        // shared palettes
    std::vector<uint32_t> local(first.size(), 0);
    std::vector<uint32_t> seen(first.size(), UINT32_MAX);  // block index that last listed this id
    uint64_t bitCursor = 0;
    for (const Segment& s : segments) {
        PaletteBlock block{s.start, 0, 0, PaletteBlock::kDirect};
        if (s.omega == kWhole) {
            const unsigned bits = unsigned(std::max(1, int(std::bit_width(first.size() > 1 ? first.size() - 1 : 1))));
            block.paletteOffset = PaletteBlock::kWholeMaterialArray;
            block.indexBits = uint8_t(bits);
            block.dataOffset = bitCursor;
            reserveBits(out.indexBits, bitCursor + s.length * bits);
            for (uint64_t i = s.start; i < s.start + s.length; ++i, bitCursor += bits) putBits(out.indexBits, bitCursor, material[ids[i]], bits);
        } else if (s.omega == PaletteBlock::kDirect) {
            block.dataOffset = out.direct.size();
            out.direct.insert(out.direct.end(), values.begin() + long(s.start * valueSize), values.begin() + long((s.start + s.length) * valueSize));
        } else {
            std::vector<uint32_t> palette;
            const uint32_t blockIndex = uint32_t(out.blocks.size());
            for (uint64_t i = s.start; i < s.start + s.length; ++i) {
                if (seen[ids[i]] == blockIndex) continue;
                seen[ids[i]] = blockIndex;
                palette.push_back(material[ids[i]]);
            }
            std::sort(palette.begin(), palette.end());  // at most 256 distinct entries
            const unsigned bits = palette.size() <= 1 ? 0 : unsigned(std::bit_width(palette.size() - 1));
            block.paletteOffset = paletteAt.findOrAdd(palette, out.palettes);
            block.indexBits = uint8_t(bits);
            block.dataOffset = bitCursor;
            reserveBits(out.indexBits, bitCursor + s.length * bits);
            for (size_t k = 0; k < palette.size(); ++k) local[palette[k]] = uint32_t(k);
            for (uint64_t i = s.start; i < s.start + s.length; ++i, bitCursor += bits)
                putBits(out.indexBits, bitCursor, local[material[ids[i]]], bits);
        }
        out.blocks.push_back(block);
    }
    out.indexBits.resize((bitCursor + 63) / 64 + 1, 0);
    return out;
}

ChannelStats channelStats(std::span<const uint8_t> values, uint32_t valueSize, const PaletteChannel& channel) {
    ChannelStats s;
    if (!valueSize) return s;
    s.entries = values.size() / valueSize;
    std::vector<uint64_t> first;
    distinctIds(values, valueSize, s.entries, first);
    s.unique = first.size();
    s.rawBytes = values.size();
    const uint64_t bits = s.unique > 1 ? std::bit_width(s.unique - 1) : 0;
    s.materialIndexBytes = s.unique * valueSize + (s.entries * bits + 7) / 8;
    s.paletteBytes = channel.byteSize();
    for (const PaletteBlock& b : channel.blocks) (b.indexBits == PaletteBlock::kDirect ? s.directBlocks : s.paletteBlocks)++;
    std::set<uint32_t> stored;
    for (const PaletteBlock& b : channel.blocks)
        if (b.indexBits != PaletteBlock::kDirect && b.paletteOffset != PaletteBlock::kWholeMaterialArray) stored.insert(b.paletteOffset);
    s.palettesStored = stored.size();
    return s;
}

} // namespace vdbdag::attributes
