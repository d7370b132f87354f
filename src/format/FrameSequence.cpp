#include "src/format/FrameSequence.h"

#include <cstring>
#include <limits>

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
    return list;
}

uint64_t writeSequence(std::span<const FramePart> parts, std::ostream& out) {
    if (parts.empty()) throw Error("a sequence file needs at least one frame");
    std::vector<Section> sections(2);  // FileInfo and Frames, filled once the grids are counted
    std::vector<FrameEntry> frames;
    std::vector<uint8_t> fileInfo;
    uint64_t grids = 0;
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
                // Its writer string is kept; the count becomes the sequence's.
                if (fileInfo.empty()) fileInfo = readContainerFile(part.path, false, {}, [](SectionKind k, uint32_t) { return k == SectionKind::FileInfo; })
                                                     .front()
                                                     .data;
                continue;
            }
            if (s.kind == SectionKind::FileMetadata) {
                s.kind = SectionKind::FrameMetadata;
                s.grid = uint32_t(grids);
            } else {
                if (s.grid >= list.gridCount) throw Error(part.path + ": a section for grid " + std::to_string(s.grid) + " of " + std::to_string(list.gridCount));
                s.grid += uint32_t(grids);
            }
            sections.push_back(std::move(s));
        }
        frames.push_back({part.number, list.gridCount});
        grids += list.gridCount;
    }
    const uint32_t count = uint32_t(grids);
    std::memcpy(fileInfo.data(), &count, sizeof count);  // (readFrameList checked it holds a u32)
    sections[0] = {SectionKind::FileInfo, 0, std::move(fileInfo)};
    sections[1] = {SectionKind::Frames, 0, serializeFrames(frames)};
    return writeContainerTo(std::move(sections), out);
}

} // namespace vdbdag::format
