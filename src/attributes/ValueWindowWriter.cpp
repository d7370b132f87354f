// See ValueWindows.h: the writer of value windows (each window palette-
// compressed on its own core, spilled to scratch when large), and the
// shares of several processes. Reading them: ValueWindows.cpp.
#include "src/attributes/ValueWindows.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <memory>
#include <new>

#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include "src/attributes/PaletteCompressor.h"
#include "src/format/ByteIO.h"
#include "src/format/ZstdFrame.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {
namespace {

// Windows of at most this many raw bytes get zstd's level 9, larger ones
// level 3 (the container's rule for whole sections).
constexpr uint64_t kSmallWindowBytes = uint64_t(4) << 20;
constexpr size_t kHeaderBytes = 4 + 8 + 8 + 8;  // value size, entries, window entries, window count

} // namespace

ValueWindowWriter::ValueWindowWriter(uint32_t valueSize, uint64_t expectedEntries, unsigned parallel, const std::string& spillNear,
                                     uint64_t spillInMemory)
    : valueSize_(valueSize), parallel_(parallel ? parallel : unsigned(std::max(1, tbb::info::default_concurrency()))) {
    if (valueSize == 0 || valueSize > 64) throw Error("internal error: a value window needs 1 to 64 bytes per value");
    // A window stored raw is its serialised channel: at most its values plus
    // the channel's fixed fields and a directory entry per block, bounded
    // here by 1/16 of the values and 4 KiB.
    const uint64_t windows = (expectedEntries + kValueWindowEntries - 1) / kValueWindowEntries;
    const uint64_t bound = kHeaderBytes + expectedEntries * valueSize + expectedEntries * valueSize / 16 + windows * (4096 + 16);
    if (!spillNear.empty()) {
        spill_ = std::make_shared<ScratchFile>(spillNear, spillInMemory);
        const uint8_t zeros[kHeaderBytes] = {};
        spill_->append(zeros, kHeaderBytes);
        return;
    }
    if (expectedEntries && bound < (uint64_t(1) << 40)) payload_.reserve(size_t(bound));
    payload_.resize(kHeaderBytes);
}

void ValueWindowWriter::beginShare(uint64_t firstEntry, bool endsLayer) {
    if (entries_ || !pending_.empty() || !directory_.empty() || spill_) throw Error("internal error: a share begins before the first entry");
    share_ = true;
    endsLayer_ = endsLayer;
    entries_ = firstEntry;
    headEnd_ = (firstEntry + kValueWindowEntries - 1) / kValueWindowEntries * kValueWindowEntries;
    head_.window = firstEntry / kValueWindowEntries;
    payload_.clear();  // coded windows only: process 0 writes the header
}

void ValueWindowWriter::add(std::span<const uint8_t> values) {
    if (values.size() % valueSize_) throw Error("internal error: values are not whole entries");
    if (rangeType_) range_.add(*rangeType_, values);
    if (share_ && entries_ < headEnd_ && !values.empty()) {  // the window this share starts inside
        const size_t take = size_t(std::min<uint64_t>(headEnd_ - entries_, values.size() / valueSize_) * valueSize_);
        head_.values.insert(head_.values.end(), values.begin(), values.begin() + long(take));
        entries_ += take / valueSize_;
        values = values.subspan(take);
    }
    const uint64_t windowBytes = kValueWindowEntries * valueSize_;
    while (!values.empty()) {
        if (pending_.empty() || pending_.back().size() == windowBytes) {
            if (pending_.size() == parallel_) codePending();  // every pending window is full
            pending_.emplace_back();
            pending_.back().reserve(size_t(windowBytes));  // untouched until filled: never copied while it grows
        }
        std::vector<uint8_t>& w = pending_.back();
        const size_t take = size_t(std::min<uint64_t>(windowBytes - w.size(), values.size()));
        w.insert(w.end(), values.begin(), values.begin() + long(take));
        values = values.subspan(take);
        entries_ += take / valueSize_;
    }
}

void ValueWindowWriter::codePending() {
    struct Coded {
        std::vector<uint8_t> stored;
        uint64_t rawBytes = 0, estimate = 0;
    };
    std::vector<Coded> coded(pending_.size());
    // Each window on its own core (compressPalette parallelises inside a
    // window too); the result is the same for any number of threads.
    for (const std::vector<uint8_t>& w : pending_) codedEntries_.push_back(w.size() / valueSize_);
    tbb::parallel_for(size_t(0), pending_.size(), [&](size_t i) {
        std::vector<uint8_t> raw = serializePalette(compressPalette(pending_[i], valueSize_));
        std::vector<uint8_t>().swap(pending_[i]);
        Coded& c = coded[i];
        c.rawBytes = raw.size();
        c.estimate = format::zstdFastSize(raw);
        c.stored = format::zstdCompressIfSmaller(raw, {raw.size() <= kSmallWindowBytes ? 9 : 3, /*checksum: a reader may inflate one window*/ true, 0});
        if (c.stored.empty()) c.stored = std::move(raw);
    });
    pending_.clear();
    for (Coded& c : coded) {
        appendWindow(payload_, spill_.get(), c.stored);
        directory_.push_back({c.stored.size(), c.rawBytes});
        estimate_ += c.estimate;
        std::vector<uint8_t>().swap(c.stored);
    }
}

ValueWindowsPayload ValueWindowWriter::finish() {
    if (!pending_.empty()) codePending();
    format::ByteWriter head;
    head.put<uint32_t>(valueSize_);
    head.put<uint64_t>(entries_);
    head.put<uint64_t>(kValueWindowEntries);
    head.put<uint64_t>(directory_.size());
    format::ByteWriter dir;
    for (const auto& [stored, raw] : directory_) {
        dir.put<uint64_t>(stored);
        dir.put<uint64_t>(raw);
    }
    estimate_ += kHeaderBytes + dir.bytes().size();
    directory_.clear();
    ValueWindowsPayload out = sealWindows(std::move(payload_), std::move(spill_), head.bytes(), dir.bytes());
    if (rangeType_) out.range = range_;
    return out;
}

void appendWindow(std::vector<uint8_t>& payload, ScratchFile* spill, std::span<const uint8_t> bytes) {
    if (spill) spill->append(bytes.data(), bytes.size());
    else payload.insert(payload.end(), bytes.begin(), bytes.end());
}

ValueWindowsPayload sealWindows(std::vector<uint8_t>&& payload, std::shared_ptr<ScratchFile>&& spill, std::span<const uint8_t> header,
                                std::span<const uint8_t> directory) {
    ValueWindowsPayload out;
    if (spill) {
        spill->overwrite(0, header.data(), header.size());
        spill->append(directory.data(), directory.size());
        out.file = std::move(spill);
        return out;
    }
    if (payload.size() < header.size()) throw Error("internal error: a window payload without its header placeholder");
    std::memcpy(payload.data(), header.data(), header.size());
    payload.insert(payload.end(), directory.begin(), directory.end());
    out.bytes = std::move(payload);
    return out;
}

ShareWindows ValueWindowWriter::finishShare() {
    if (!share_) throw Error("internal error: finishShare without beginShare");
    ShareWindows out;
    const uint64_t windowBytes = kValueWindowEntries * valueSize_;
    // The last window is whole here when it is full or ends the layer.
    if (!pending_.empty() && !endsLayer_ && pending_.back().size() != windowBytes) {
        out.tail.window = (entries_ - pending_.back().size() / valueSize_) / kValueWindowEntries;
        out.tail.values = std::move(pending_.back());
        pending_.pop_back();
    }
    codePending();
    out.firstWindow = headEnd_ / kValueWindowEntries;
    for (size_t i = 0; i < directory_.size(); ++i) out.directory.push_back({directory_[i].first, directory_[i].second, codedEntries_[i]});
    out.coded = std::move(payload_);
    out.head = std::move(head_);
    if (rangeType_) out.range = range_;
    directory_.clear();
    return out;
}

void ValueWindowWriter::addShare(const ShareWindows& share) {
    if (rangeType_ && share.range) range_.merge(*rangeType_, *share.range);
    add(share.head.values);
    uint64_t at = 0;
    for (size_t j = 0; j < share.directory.size(); ++j) {
        const ShareWindows::Coded& c = share.directory[j];
        if (c.stored > share.coded.size() - at) throw Error("internal error: a process's coded windows are cut short");
        addCoded(share.firstWindow + j, c, std::span<const uint8_t>(share.coded).subspan(size_t(at), size_t(c.stored)));
        at += c.stored;
    }
    add(share.tail.values);
}

void ValueWindowWriter::addCoded(uint64_t window, const ShareWindows::Coded& coded, std::span<const uint8_t> bytes) {
    const uint64_t windowBytes = kValueWindowEntries * valueSize_;
    if (entries_ != window * kValueWindowEntries || (!pending_.empty() && pending_.back().size() != windowBytes) || bytes.size() != coded.stored)
        throw Error("internal error: a coded window out of place");
    codePending();
    appendWindow(payload_, spill_.get(), bytes);
    directory_.push_back({coded.stored, coded.raw});
    codedEntries_.push_back(coded.entries);
    entries_ += coded.entries;
}

std::vector<uint8_t> ShareWindows::serialize() const {
    format::ByteWriter w;
    w.put<uint64_t>(firstWindow);
    w.put<uint64_t>(directory.size());
    for (const Coded& c : directory) {
        w.put<uint64_t>(c.stored);
        w.put<uint64_t>(c.raw);
        w.put<uint64_t>(c.entries);
    }
    w.put<uint64_t>(coded.size());
    w.putBytes(coded);
    for (const Loose* l : {&head, &tail}) {
        w.put<uint64_t>(l->window);
        w.put<uint64_t>(l->values.size());
        w.putBytes(l->values);
        w.put<uint64_t>(l->layout.size());
        for (uint64_t m : l->layout) w.put<uint64_t>(m);
        w.put<uint64_t>(l->places.size());
        for (const coding::BrickPlace& p : l->places) w.put(p);
    }
    w.put<uint8_t>(range ? 1 : 0);
    if (range) {
        w.put<uint64_t>(range->min.size());
        w.putBytes(range->min);
        w.putBytes(range->max);
    }
    return w.take();
}

ShareWindows ShareWindows::deserialize(std::span<const uint8_t> bytes) {
    format::ByteReader r(bytes, "a process's value windows");
    ShareWindows s;
    s.firstWindow = r.get<uint64_t>();
    const uint64_t n = r.get<uint64_t>();
    if (n > r.remaining() / 24) r.fail("directory runs past the end");
    s.directory.resize(size_t(n));
    for (Coded& c : s.directory) {
        c.stored = r.get<uint64_t>();
        c.raw = r.get<uint64_t>();
        c.entries = r.get<uint64_t>();
    }
    s.coded = r.getArray<uint8_t>(r.get<uint64_t>());
    for (Loose* l : {&s.head, &s.tail}) {
        l->window = r.get<uint64_t>();
        l->values = r.getArray<uint8_t>(r.get<uint64_t>());
        l->layout = r.getArray<uint64_t>(r.get<uint64_t>());
        l->places = r.getArray<coding::BrickPlace>(r.get<uint64_t>());
    }
    if (r.get<uint8_t>()) {
        ValueRange range;
        const uint64_t n = r.get<uint64_t>();
        range.min = r.getArray<uint8_t>(n);
        range.max = r.getArray<uint8_t>(n);
        s.range = std::move(range);
    }
    r.expectEnd();
    return s;
}

std::vector<uint8_t> encodeValueWindows(std::span<const uint8_t> values, uint32_t valueSize, uint64_t* estimate) {
    if (estimate) *estimate = 0;
    if (valueSize == 0) return {};  // a mask grid stores no values
    ValueWindowWriter writer(valueSize, values.size() / valueSize);
    writer.add(values);
    std::vector<uint8_t> out = std::move(writer.finish().bytes);
    if (estimate) *estimate = writer.estimate();
    return out;
}

} // namespace vdbdag::attributes
