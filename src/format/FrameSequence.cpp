#include "src/format/FrameSequence.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>

#include "src/format/ByteIO.h"
#include "src/util/Error.h"

namespace vdbdag::format {

std::vector<uint8_t> serializeFrames(std::span<const FrameEntry> frames) {
    ByteWriter w;
    w.put<uint32_t>(uint32_t(frames.size()));
    for (const FrameEntry& f : frames) {
        w.put<int64_t>(f.number);
        w.put<uint32_t>(f.gridCount);
    }
    return w.take();
}

std::vector<FrameEntry> parseFrames(std::span<const uint8_t> payload, uint64_t gridCount, const std::string& what) {
    ByteReader r(payload, what);
    const uint32_t n = r.get<uint32_t>();
    if (n == 0) r.fail("no frames");
    if (uint64_t(n) * 12 > r.remaining()) r.fail("claims " + std::to_string(n) + " frames, more than it holds");
    std::vector<FrameEntry> frames(n);
    uint64_t grids = 0;
    for (uint32_t i = 0; i < n; ++i) {
        frames[i].number = r.get<int64_t>();
        frames[i].gridCount = r.get<uint32_t>();
        if (frames[i].gridCount == 0) r.fail("frame " + std::to_string(frames[i].number) + " holds no grid");
        if (i > 0 && frames[i].number <= frames[i - 1].number)
            r.fail("frame numbers out of order (" + std::to_string(frames[i - 1].number) + " then " + std::to_string(frames[i].number) + ")");
        grids += frames[i].gridCount;
    }
    r.expectEnd();
    if (grids != gridCount) r.fail("its frames hold " + std::to_string(grids) + " grids but the file has " + std::to_string(gridCount));
    return frames;
}

namespace {

bool isGridKind(SectionKind kind) {
    return kind != SectionKind::FileInfo && kind != SectionKind::Frames && kind != SectionKind::FileMetadata && kind != SectionKind::FrameMetadata &&
           kind != SectionKind::SameAs && isKnownKind(kind);
}

} // namespace

std::vector<uint8_t> serializeSameAs(std::span<const SameAsEntry> entries) {
    ByteWriter w;
    w.put<uint32_t>(uint32_t(entries.size()));
    for (const SameAsEntry& e : entries) {
        w.put<uint32_t>(uint32_t(e.kind));
        w.put<uint32_t>(e.grid);
    }
    return w.take();
}

std::vector<SameAsEntry> parseSameAs(std::span<const uint8_t> payload, uint32_t grid, const std::string& what) {
    ByteReader r(payload, what);
    const uint32_t n = r.get<uint32_t>();
    if (n == 0 || n > 32) r.fail("names " + std::to_string(n) + " sections (1 to 32)");
    std::vector<SameAsEntry> entries(n);
    for (uint32_t i = 0; i < n; ++i) {
        entries[i].kind = SectionKind(r.get<uint32_t>());
        entries[i].grid = r.get<uint32_t>();
        if (!isGridKind(entries[i].kind)) r.fail("names section kind " + std::to_string(uint32_t(entries[i].kind)) + ", not a grid's");
        if (entries[i].grid >= grid)
            r.fail("takes grid " + std::to_string(grid) + "'s " + sectionKindName(entries[i].kind) + " from grid " + std::to_string(entries[i].grid) +
                   ", which is not an earlier grid");
        for (uint32_t j = 0; j < i; ++j)
            if (entries[j].kind == entries[i].kind) r.fail(std::string("names ") + sectionKindName(entries[i].kind) + " twice");
    }
    r.expectEnd();
    return entries;
}

namespace {

// Whether two stored payloads hold the same bytes (read a piece at a time).
bool sameStoredBytes(const StoredPayload& a, const StoredPayload& b) {
    if (a.storedBytes != b.storedBytes || a.rawBytes != b.rawBytes || a.checksum != b.checksum || a.zstd != b.zstd) return false;
    std::ifstream fa(a.path, std::ios::binary), fb(b.path, std::ios::binary);
    fa.seekg(std::streamoff(a.offset));
    fb.seekg(std::streamoff(b.offset));
    std::vector<char> pa(size_t(1) << 20), pb(pa.size());
    for (uint64_t left = a.storedBytes; left > 0;) {
        const size_t n = size_t(std::min<uint64_t>(left, pa.size()));
        if (!fa.read(pa.data(), std::streamsize(n)) || !fb.read(pb.data(), std::streamsize(n))) throw Error(a.path + ": cannot be read back");
        if (std::memcmp(pa.data(), pb.data(), n) != 0) return false;
        left -= n;
    }
    return true;
}

// The grid count of a FileInfo payload.
uint32_t fileInfoGrids(std::span<const uint8_t> payload, const std::string& what) {
    ByteReader r(payload, what);
    return r.get<uint32_t>();
}

} // namespace

FrameList readFrameList(const std::string& path) {
    const std::vector<Section> head = readContainerFile(path, false, {}, [](SectionKind kind, uint32_t) {
        return kind == SectionKind::FileInfo || kind == SectionKind::Frames;
    });
    const Section* info = nullptr;
    const Section* frames = nullptr;
    for (const Section& s : head) {
        const Section*& slot = s.kind == SectionKind::FileInfo ? info : frames;
        if (slot) throw Error(path + ": two " + sectionKindName(s.kind) + " sections");
        slot = &s;
    }
    if (!info) throw Error(path + ": missing FileInfo section");
    FrameList list;
    list.gridCount = fileInfoGrids(info->data, path + ": FileInfo");
    list.sequence = frames != nullptr;
    if (frames) list.frames = parseFrames(frames->data, list.gridCount, path + ": Frames");
    else list.frames = {FrameEntry{0, list.gridCount}};
    list.fileInfo = info->data;
    return list;
}

GridRange frameGrids(std::span<const FrameEntry> frames, uint32_t gridCount, uint32_t index, const std::string& what) {
    const size_t count = frames.empty() ? 1 : frames.size();
    if (index >= count) throw Error(what + ": has " + std::to_string(count) + " frame(s); frame index " + std::to_string(index) + " asked for");
    if (frames.empty()) return {0, gridCount};
    GridRange range;
    for (uint32_t f = 0; f < index; ++f) range.first += frames[f].gridCount;
    range.end = range.first + frames[index].gridCount;
    return range;
}

uint64_t writeSequence(std::span<const FramePart> parts, std::ostream& out) {
    if (parts.empty()) throw Error("a sequence file needs at least one frame");
    std::vector<Section> sections(2);  // FileInfo and Frames, filled once the grids are counted
    std::vector<FrameEntry> frames;
    std::vector<uint8_t> fileInfo;
    uint64_t grids = 0;
    // The sections stored so far by their stored size and checksum (indices
    // into `sections`), and each grid's SameAs section being filled.
    std::map<std::pair<uint64_t, uint64_t>, std::vector<size_t>> stored;
    std::map<uint32_t, std::pair<size_t, std::vector<SameAsEntry>>> sameAs;
    for (size_t i = 0; i < parts.size(); ++i) {
        const FramePart& part = parts[i];
        if (i > 0 && part.number <= parts[i - 1].number)
            throw Error(part.path + ": frame " + std::to_string(part.number) + " comes after frame " + std::to_string(parts[i - 1].number));
        const FrameList list = readFrameList(part.path);
        if (list.sequence) throw Error(part.path + ": is a sequence already; a frame of a sequence is a file of one volume");
        if (list.gridCount == 0) throw Error(part.path + ": has no grids");
        if (grids + list.gridCount > std::numeric_limits<uint32_t>::max()) throw Error(part.path + ": too many grids for one .ssvdag file");
        std::vector<Section> own = storedSectionsOf(part.path);
        for (Section& s : own) {
            if (s.kind == SectionKind::FileInfo) {
                if (fileInfo.empty()) fileInfo = list.fileInfo;  // its writer string is kept; the count becomes the sequence's
                continue;
            }
            if (s.kind == SectionKind::FileMetadata) {
                s.kind = SectionKind::FrameMetadata;
                s.grid = uint32_t(grids);
            } else {
                if (s.grid >= list.gridCount) throw Error(part.path + ": a section for grid " + std::to_string(s.grid) + " of " + std::to_string(list.gridCount));
                s.grid += uint32_t(grids);
            }
            // Stored once: a grid's section equal to an earlier frame's
            // (worth it above the 8 bytes a SameAs entry takes).
            if (i > 0 && isGridKind(s.kind) && s.stored->storedBytes > 8) {
                const auto it = stored.find({s.stored->storedBytes, s.stored->checksum});
                const size_t* same = nullptr;
                if (it != stored.end())
                    for (const size_t& k : it->second)
                        if (sections[k].kind == s.kind && sections[k].grid < uint32_t(grids) && sameStoredBytes(*sections[k].stored, *s.stored)) {
                            same = &k;
                            break;
                        }
                if (same) {
                    auto [entry, fresh] = sameAs.try_emplace(s.grid);
                    if (fresh) {
                        entry->second.first = sections.size();  // its place: where the first section it stands for was
                        sections.push_back({SectionKind::SameAs, s.grid, {}});
                    }
                    entry->second.second.push_back({s.kind, sections[*same].grid});
                    continue;
                }
            }
            if (s.stored && isGridKind(s.kind)) stored[{s.stored->storedBytes, s.stored->checksum}].push_back(sections.size());
            sections.push_back(std::move(s));
        }
        frames.push_back({part.number, list.gridCount});
        grids += list.gridCount;
    }
    for (auto& [grid, entry] : sameAs) sections[entry.first].data = serializeSameAs(entry.second);
    const uint32_t count = uint32_t(grids);
    std::memcpy(fileInfo.data(), &count, sizeof count);  // (readFrameList checked it holds a u32)
    sections[0] = {SectionKind::FileInfo, 0, std::move(fileInfo)};
    sections[1] = {SectionKind::Frames, 0, serializeFrames(frames)};
    return writeContainerTo(std::move(sections), out);
}

} // namespace vdbdag::format
