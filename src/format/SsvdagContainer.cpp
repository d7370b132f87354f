// The .ssvdag container (see SsvdagContainer.h). Byte layout, little-endian,
// offsets from the start of the file:
//
//   offset   size  field
//   0        8     magic 89 53 53 56 44 41 47 0A  ("\x89SSVDAG\n"): the high
//                  first byte catches 7-bit channels and text sniffing, the
//                  final LF catches CRLF / LF translation, as in PNG
//   8        4     u32 format version (1)
//   12       4     u32 section count N
//   16       48*N  section table; entry i starts at 16 + 48*i:
//                    +0   u32 kind (SectionKind)
//                    +4   u32 grid index (0 for file-level sections)
//                    +8   u32 codec: 0 = raw, 1 = zstd (one frame with its
//                                    content size in the frame header)
//                    +12  u32 reserved, 0
//                    +16  u64 payload offset (from the start of the file)
//                    +24  u64 stored size (bytes in the file)
//                    +32  u64 raw size (bytes once restored)
//                    +40  u64 xxh3-64 (XXH3_64bits, seed 0) of the stored bytes
//   16+48N   8     u64 xxh3-64 of bytes [0, 16+48N): header and table
//   24+48N   ...   payloads, in table order, back to back: payload 0 starts
//                  at 24+48N, payload i+1 where payload i ends, and the last
//                  one ends at the end of the file
//
// Every byte of a file is therefore covered by the magic, the table checksum
// or one payload checksum, so any corruption is detected.
//
// Writer: with ContainerOptions::compress a section of more than 64 bytes is
// zstd-compressed at options.zstdLevel (sections over 4 MiB at
// min(level, 3) on two worker threads, so value channels do not dominate the
// encode time) and kept raw when zstd does not make it smaller.
//
// Reader, in this order and before using any of it: the magic; the version;
// that the table for N sections fits the file; the table checksum; per entry
// the codec, the reserved field, the payload bounds (overflow-safe), that the
// payload starts exactly where the previous one ended (no overlap, no gap),
// the raw size against what the codec can produce from the stored size (raw
// == stored for raw; raw <= stored * 2^16 + 4096 for zstd); that nothing
// follows the last payload. Then per section: the payload checksum, and for
// zstd that the payload is exactly one frame declaring the raw size, before
// allocating the raw size and decompressing into it, and that decompression
// yields exactly that many bytes. Each failure is a vdbdag::Error with a
// one-line message starting with the source name; no allocation exceeds what
// the file's own size justifies through these bounds.
#include "src/format/SsvdagContainer.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <limits>
#include <memory>
#include <new>
#include <ostream>
#include <sys/stat.h>
#include <unistd.h>

#include <xxhash.h>
#include <zstd.h>
#include <zstd_errors.h>

#include "src/format/ByteIO.h"
#include "src/format/ZstdFrame.h"
#include "src/util/Error.h"
#include "src/util/InputPath.h"

namespace vdbdag::format {
namespace {

constexpr uint8_t kMagic[8] = {0x89, 'S', 'S', 'V', 'D', 'A', 'G', '\n'};
constexpr uint64_t kHeaderBytes = 16;
constexpr uint64_t kEntryBytes = 48;
constexpr uint64_t kChecksumBytes = 8;
constexpr uint32_t kCodecRaw = 0, kCodecZstd = 1;
constexpr size_t kMinBytesToCompress = 64;
constexpr size_t kLargeSection = size_t(4) << 20;

struct Entry {
    uint32_t kind, grid, codec, reserved;
    uint64_t offset, stored, raw, checksum;
};

std::string num(uint64_t v) { return std::to_string(v); }

// "section 3 ('DagInner' of grid 0)"; unknown kinds by number.
std::string describe(size_t index, uint32_t kind, uint32_t grid) {
    const char* name = sectionKindName(SectionKind(kind));
    std::string text = "section " + num(index) + " (";
    if (std::strcmp(name, "unknown") == 0) {
        text += "kind ";
        text += num(kind);
    } else {
        text += '\'';
        text += name;
        text += '\'';
    }
    text += " of grid ";
    text += num(grid);
    text += ')';
    return text;
}

// What a file that is not an .ssvdag is, by its first bytes, when it is a
// format vdbdag reads (an .ssvdag command given the input of `encode`), with
// the command that takes it; empty otherwise.
std::string foreignFormatOf(std::span<const uint8_t> b, const std::string& name) {
    auto starts = [&](size_t at, const char* text) {
        const size_t n = std::strlen(text);
        return b.size() >= at + n && std::memcmp(b.data() + at, text, n) == 0;
    };
    std::string what, also;
    const std::string scan = " (`info`, `diff`, `render` and `import` take it as it is)";
    if (starts(0, "\x20\x42\x44\x56")) what = "an OpenVDB .vdb file", also = " (`info`, `diff`, `verify` and `render` take it as it is)";  // magic 0x56444220, LE
    else if (starts(0, "NanoVDB")) what = "a NanoVDB file", also = " (`info`, `diff` and `render` take it as it is)";
    else if (starts(0, "NRRD000")) what = "a NRRD file", also = scan;
    else if (starts(0, "ObjectType") || starts(0, "NDims")) what = "a MetaImage header", also = scan;
    else if (starts(128, "DICM")) what = "a DICOM file", also = scan;
    else if (starts(344, "n+1") || starts(344, "ni1") || starts(4, "n+2")) what = "a NIfTI file", also = scan;
    else if (starts(0, "\x1f\x8b")) what = "gzip-compressed data (a .nii.gz or .nrrd, if it is a scan)", also = scan;
    else if (name.size() > 4 && (name.ends_with(".raw") || name.ends_with(".RAW")))
        what = "a raw volume (by its name; its layout from the name, e.g. ct_512x512x300_int16le.raw, or --dims/--type)", also = scan;
    if (what.empty()) return "";
    return ": it is " + what + ", which `vdbdag encode " + name + " -o OUT.ssvdag` reads" + also;
}

// `bytes`: the file, or (readContainerFile) at least its header, table and
// table checksum; `size`: the file's size.
std::vector<Entry> parseTable(std::span<const uint8_t> bytes, const std::string& name, uint64_t size) {
    auto fail = [&](const std::string& why) { throw Error(name + ": " + why); };
    if (size < sizeof(kMagic)) {
        // A prefix of the magic is a truncated file; anything else is not ours.
        if (size == 0 || std::memcmp(bytes.data(), kMagic, size) == 0)  // (no memcmp on a null pointer)
            fail("truncated: the file has " + num(size) + " bytes, the header alone needs " + num(kHeaderBytes + kChecksumBytes));
        fail("not an .ssvdag file (bad magic)");
    }
    if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
        if (std::memcmp(bytes.data() + 1, kMagic + 1, 6) == 0 && bytes[7] == '\r')
            fail("not an .ssvdag file (bad magic: line endings were translated, copy it in binary mode)");
        const std::string foreign = foreignFormatOf(bytes, name);
        fail(foreign.empty() ? "not an .ssvdag file (bad magic)" : "not an .ssvdag file" + foreign);
    }
    if (size < kHeaderBytes + kChecksumBytes)
        fail("truncated: the file has " + num(size) + " bytes, the header alone needs " + num(kHeaderBytes + kChecksumBytes));
    ByteReader header(bytes.subspan(8, 8), name);
    const uint32_t version = header.get<uint32_t>();
    const uint32_t count = header.get<uint32_t>();
    if (version < kFormatVersion || version > kLatestFormatVersion)
        fail("unsupported format version " + num(version) + " (this vdbdag reads versions " + num(kFormatVersion) + " to " + num(kLatestFormatVersion) + ")");
    // count < 2^32, so this cannot overflow.
    const uint64_t tableEnd = kHeaderBytes + uint64_t(count) * kEntryBytes;
    if (tableEnd + kChecksumBytes > size)
        fail("truncated: the table of " + num(count) + " sections ends at byte " + num(tableEnd + kChecksumBytes) + " but the file has " +
             num(size) + " bytes");
    ByteReader tail(bytes.subspan(tableEnd, kChecksumBytes), name);
    if (tail.get<uint64_t>() != XXH3_64bits(bytes.data(), tableEnd))
        fail("checksum mismatch in the header or section table: the file is corrupted");

    std::vector<Entry> entries;
    entries.reserve(count);  // bounded by size / 48 above
    ByteReader r(bytes.subspan(kHeaderBytes, tableEnd - kHeaderBytes), name);
    uint64_t expectedOffset = tableEnd + kChecksumBytes;
    for (uint32_t i = 0; i < count; ++i) {
        Entry e{};
        e.kind = r.get<uint32_t>();
        e.grid = r.get<uint32_t>();
        e.codec = r.get<uint32_t>();
        e.reserved = r.get<uint32_t>();
        e.offset = r.get<uint64_t>();
        e.stored = r.get<uint64_t>();
        e.raw = r.get<uint64_t>();
        e.checksum = r.get<uint64_t>();
        const std::string what = describe(i, e.kind, e.grid);
        if (e.codec != kCodecRaw && e.codec != kCodecZstd) fail(what + " has unknown codec " + num(e.codec));
        if (e.reserved != 0) fail(what + " has a non-zero reserved field " + num(e.reserved));
        if (e.offset > size) fail("truncated: " + what + " starts at byte " + num(e.offset) + " but the file has " + num(size) + " bytes");
        if (e.stored > std::numeric_limits<uint64_t>::max() - e.offset)
            fail(what + " claims an impossible size of " + num(e.stored) + " bytes at byte " + num(e.offset));
        const uint64_t end = e.offset + e.stored;
        if (end > size) fail("truncated: " + what + " ends at byte " + num(end) + " but the file has " + num(size) + " bytes");
        if (e.offset < expectedOffset) {
            if (e.offset < tableEnd + kChecksumBytes)
                fail(what + " starts at byte " + num(e.offset) + ", inside the header and table that end at byte " + num(tableEnd + kChecksumBytes));
            fail(what + " starts at byte " + num(e.offset) + " and overlaps section " + num(i - 1) + " which ends at byte " + num(expectedOffset));
        }
        if (e.offset > expectedOffset)
            fail(what + " starts at byte " + num(e.offset) + ", leaving " + num(e.offset - expectedOffset) + " unaccounted bytes after byte " +
                 num(expectedOffset));
        if (e.codec == kCodecRaw && e.raw != e.stored)
            fail(what + " claims " + num(e.raw) + " raw bytes for " + num(e.stored) + " bytes stored uncompressed");
        // e.stored <= size < 2^48 in practice, but stay overflow-safe anyway.
        if (e.codec == kCodecZstd && !zstdCanProduce(e.stored, e.raw))
            fail(what + " claims " + num(e.raw) + " bytes from " + num(e.stored) + " compressed bytes, which zstd cannot produce");
        expectedOffset = end;
        entries.push_back(e);
    }
    if (expectedOffset != size) fail(num(size - expectedOffset) + " unexpected bytes after the last section (at byte " + num(expectedOffset) + ")");
    return entries;
}

bool isUnknownKind(uint32_t kind) { return !isKnownKind(SectionKind(kind)); }

// What the sections to be kept claim to inflate to, against --max-memory,
// before any is inflated (a zstd frame inflates to exactly its declared size).
void checkInflatedSize(const std::vector<Entry>& entries, bool unknownKinds, const ReadLimits& limits, const std::string& sourceName) {
    uint64_t total = 0;
    for (const Entry& e : entries)
        if (unknownKinds || !isUnknownKind(e.kind)) total = saturatingAdd(total, e.raw);
    checkMemory(limits, total, sourceName, "its sections, inflated,");
}

std::vector<uint8_t> restore(const Entry& e, std::span<const uint8_t> stored, const std::string& what) {
    if (XXH3_64bits(stored.data(), stored.size()) != e.checksum) throw Error(what + ": checksum mismatch, the file is corrupted");
    if (e.codec == kCodecRaw) return std::vector<uint8_t>(stored.begin(), stored.end());
    return zstdInflateFrame(stored, e.raw, what);  // raw <= stored * 2^16 + 4096 (parseTable)
}

// The section's zstd frame, or empty when zstd does not make it smaller.
std::vector<uint8_t> compressSection(std::span<const uint8_t> data, const ContainerOptions& options) {
    const bool large = data.size() > kLargeSection;
    return zstdCompressIfSmaller(data, {large ? std::min(options.zstdLevel, 3) : options.zstdLevel, false, large ? 2 : 0});
}

} // namespace

uint64_t storedSectionBytes(std::span<const uint8_t> raw, const ContainerOptions& options) {
    if (!options.compress || raw.size() < kMinBytesToCompress) return raw.size();
    const std::vector<uint8_t> frame = compressSection(raw, options);
    return frame.empty() ? raw.size() : frame.size();
}

const char* sectionKindName(SectionKind kind) {
    switch (kind) {
        case SectionKind::FileInfo: return "FileInfo";
        case SectionKind::FileMetadata: return "FileMetadata";
        case SectionKind::Frames: return "Frames";
        case SectionKind::FrameMetadata: return "FrameMetadata";
        case SectionKind::SameAs: return "SameAs";
        case SectionKind::Summary: return "Summary";
        case SectionKind::InactiveSignedFill: return "InactiveSignedFill";
        case SectionKind::GridInfo: return "GridInfo";
        case SectionKind::VdbDescriptor: return "VdbDescriptor";
        case SectionKind::DagLevels: return "DagLevels";
        case SectionKind::DagInner: return "DagInner";
        case SectionKind::DagLeaves: return "DagLeaves";
        case SectionKind::DagStats: return "DagStats";
        case SectionKind::Values: return "Values";
        case SectionKind::InactiveLevels: return "InactiveLevels";
        case SectionKind::InactiveInner: return "InactiveInner";
        case SectionKind::InactiveLeaves: return "InactiveLeaves";
        case SectionKind::InactiveValues: return "InactiveValues";
        case SectionKind::ValueErrors: return "ValueErrors";
        case SectionKind::ColourErrors: return "ColourErrors";
        case SectionKind::Normals: return "Normals";
        case SectionKind::PredictedValues: return "PredictedValues";
        case SectionKind::InactivePredictedValues: return "InactivePredictedValues";
        case SectionKind::ValueWindows: return "ValueWindows";
        case SectionKind::InactiveValueWindows: return "InactiveValueWindows";
        case SectionKind::PredictedWindows: return "PredictedWindows";
        case SectionKind::InactivePredictedWindows: return "InactivePredictedWindows";
        case SectionKind::ValueReference: return "ValueReference";
    }
    return "unknown";
}

bool isKnownKind(SectionKind kind) { return std::strcmp(sectionKindName(kind), "unknown") != 0; }

uint32_t formatVersionOf(std::span<const Section> sections) {
    uint32_t version = kFormatVersion;
    for (const Section& s : sections) {
        if (s.kind == SectionKind::ValueReference) return 3;
        if (s.kind == SectionKind::InactiveSignedFill) version = 2;
    }
    return version;
}

bool isPrecompressed(SectionKind kind) {
    return kind == SectionKind::ValueWindows || kind == SectionKind::InactiveValueWindows || kind == SectionKind::PredictedWindows ||
           kind == SectionKind::InactivePredictedWindows;
}

namespace {

// An open regular file (O_NONBLOCK: opening a FIFO must not block; it is
// refused), closed when done.
struct InputFile {
    int fd = -1;
    uint64_t size = 0;
    explicit InputFile(const std::string& path) {
        auto fail = [&](const std::string& why, int err) { throw Error(path + ": " + why + " (" + std::strerror(err) + ")"); };
        fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
        if (fd < 0) {
            const int err = errno;
            if (err == ENOENT || err == ENOTDIR) throw Error(path + ": no such file");
            fail("cannot be opened for reading", err);
        }
        struct stat st{};
        if (::fstat(fd, &st) != 0) {
            const int err = errno;
            ::close(fd);
            fail("cannot be read", err);
        }
        if (!S_ISREG(st.st_mode)) {
            ::close(fd);
            throw Error(path + ": is " + fileKindName(st.st_mode) + ", not an .ssvdag file");  // a device could be read forever, a FIFO block
        }
        size = uint64_t(st.st_size);
    }
    ~InputFile() { ::close(fd); }
    InputFile(const InputFile&) = delete;
    InputFile& operator=(const InputFile&) = delete;
    // Up to `n` bytes at `offset` (fewer when the file shrank meanwhile).
    std::vector<uint8_t> read(uint64_t offset, uint64_t n, const std::string& path) const {
        std::vector<uint8_t> bytes(static_cast<size_t>(n));
        size_t done = 0;
        while (done < bytes.size()) {
            const ssize_t got = ::pread(fd, bytes.data() + done, bytes.size() - done, off_t(offset + done));
            if (got < 0) {
                if (errno == EINTR) continue;
                throw Error(path + ": read error (" + std::string(std::strerror(errno)) + ")");
            }
            if (got == 0) break;
            done += size_t(got);
        }
        bytes.resize(done);
        return bytes;
    }
};


// Compresses the sections (into `packed`, or in place when `release`: each
// raw payload is dropped once compressed), then hands the header, the table
// and each payload to `put` in file order (with `release`, dropping each
// payload once put).
template <typename Put>
uint64_t emitContainer(std::vector<Section>& sections, bool release, const ContainerOptions& options, Put&& put) {
    if (sections.size() > std::numeric_limits<uint32_t>::max()) throw Error("too many sections for one .ssvdag file: " + num(sections.size()));
    // A spilled payload is read back in pieces: once for its checksum, once to copy it.
    constexpr size_t kPiece = size_t(4) << 20;
    std::vector<uint64_t> rawSize(sections.size()), storedSize(sections.size()), checksum(sections.size());
    std::vector<uint32_t> codec(sections.size(), kCodecRaw);
    std::vector<std::vector<uint8_t>> packed(sections.size());
    auto stored = [&](size_t i) -> const std::vector<uint8_t>& { return codec[i] == kCodecZstd && !release ? packed[i] : sections[i].data; };
    // The sections zstd may shrink, compressed side by side when the caller
    // gives threads (each alone: the same frames as one after another). With
    // `release`, a frame replaces its raw bytes as soon as it is made, so
    // memory holds what one thread's loop would plus the frames in flight.
    auto compressible = [&](size_t i) {
        return !sections[i].stored && !sections[i].spilled && options.compress && sections[i].data.size() > kMinBytesToCompress &&
               !isPrecompressed(sections[i].kind);
    };
    enum : uint8_t { kUntried, kStaysRaw, kFramed, kFramedInPlace };
    std::vector<uint8_t> state(sections.size(), kUntried);
    std::vector<std::vector<uint8_t>> frames(sections.size());
    std::vector<uint64_t> rawBefore(sections.size(), 0);
    if (options.parallel) {
        std::vector<size_t> todo;
        for (size_t i = 0; i < sections.size(); ++i)
            if (compressible(i)) todo.push_back(i);
        options.parallel(todo.size(), [&](size_t k) {
            const size_t i = todo[k];
            std::vector<uint8_t> frame = compressSection(sections[i].data, options);
            if (frame.empty()) {
                state[i] = kStaysRaw;
            } else if (release) {
                rawBefore[i] = sections[i].data.size();
                sections[i].data = std::move(frame);
                state[i] = kFramedInPlace;
            } else {
                frames[i] = std::move(frame);
                state[i] = kFramed;
            }
        });
    }
    for (size_t i = 0; i < sections.size(); ++i) {
        if (const auto& from = sections[i].stored) {  // copied as it is (its checksum is checked as it is copied)
            if (!sections[i].data.empty() || sections[i].spilled) throw Error("internal error: a copied section holds data of its own");
            codec[i] = from->zstd ? kCodecZstd : kCodecRaw;
            rawSize[i] = from->rawBytes;
            storedSize[i] = from->storedBytes;
            checksum[i] = from->checksum;
            continue;
        }
        if (const auto& file = sections[i].spilled) {
            if (!isPrecompressed(sections[i].kind) || !sections[i].data.empty()) throw Error("internal error: only a precompressed section is spilled");
            rawSize[i] = storedSize[i] = file->size();
            std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(), &XXH3_freeState);
            if (!state) throw std::bad_alloc();
            XXH3_64bits_reset(state.get());
            std::vector<uint8_t> piece;
            for (uint64_t at = 0; at < file->size(); at += kPiece) {
                file->read(at, size_t(std::min<uint64_t>(kPiece, file->size() - at)), piece);
                XXH3_64bits_update(state.get(), piece.data(), piece.size());
            }
            checksum[i] = XXH3_64bits_digest(state.get());
            continue;
        }
        const std::vector<uint8_t>& data = sections[i].data;
        rawSize[i] = state[i] == kFramedInPlace ? rawBefore[i] : data.size();
        if (state[i] == kFramedInPlace) {
            codec[i] = kCodecZstd;
        } else if (state[i] != kStaysRaw && compressible(i)) {
            std::vector<uint8_t> frame = state[i] == kFramed ? std::move(frames[i]) : compressSection(data, options);
            if (!frame.empty()) {
                codec[i] = kCodecZstd;
                (release ? sections[i].data : packed[i]) = std::move(frame);
            }
        }
        storedSize[i] = stored(i).size();
        checksum[i] = XXH3_64bits(stored(i).data(), stored(i).size());
    }
    const uint64_t tableEnd = kHeaderBytes + sections.size() * kEntryBytes;
    ByteWriter w;
    w.putBytes(std::span<const uint8_t>(kMagic, sizeof(kMagic)));
    w.put<uint32_t>(formatVersionOf(sections));
    w.put<uint32_t>(uint32_t(sections.size()));
    uint64_t offset = tableEnd + kChecksumBytes;
    for (size_t i = 0; i < sections.size(); ++i) {
        w.put<uint32_t>(uint32_t(sections[i].kind));
        w.put<uint32_t>(sections[i].grid);
        w.put<uint32_t>(codec[i]);
        w.put<uint32_t>(0);
        w.put<uint64_t>(offset);
        w.put<uint64_t>(storedSize[i]);
        w.put<uint64_t>(rawSize[i]);
        w.put<uint64_t>(checksum[i]);
        offset += storedSize[i];
    }
    w.put<uint64_t>(XXH3_64bits(w.bytes().data(), w.bytes().size()));
    put(std::span<const uint8_t>(w.bytes()));
    for (size_t i = 0; i < sections.size(); ++i) {
        if (const auto& from = sections[i].stored) {
            const InputFile file(from->path);
            std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(), &XXH3_freeState);
            if (!state) throw std::bad_alloc();
            XXH3_64bits_reset(state.get());
            for (uint64_t at = 0; at < from->storedBytes; at += kPiece) {
                const uint64_t n = std::min<uint64_t>(kPiece, from->storedBytes - at);
                const std::vector<uint8_t> piece = file.read(from->offset + at, n, from->path);
                if (piece.size() != n) throw Error(from->path + ": the file was cut short while it was copied");
                XXH3_64bits_update(state.get(), piece.data(), piece.size());
                put(std::span<const uint8_t>(piece));
            }
            if (XXH3_64bits_digest(state.get()) != from->checksum)
                throw Error(from->path + ": " + describe(i, uint32_t(sections[i].kind), sections[i].grid) + " changed while it was copied: checksum mismatch");
        } else if (const auto& file = sections[i].spilled) {
            std::vector<uint8_t> piece;
            for (uint64_t at = 0; at < file->size(); at += kPiece) {
                file->read(at, size_t(std::min<uint64_t>(kPiece, file->size() - at)), piece);
                put(std::span<const uint8_t>(piece));
            }
        } else {
            put(std::span<const uint8_t>(stored(i)));
        }
        if (release) {
            sections[i].spilled.reset();
            sections[i].stored.reset();
            std::vector<uint8_t>().swap(sections[i].data);
        }
        std::vector<uint8_t>().swap(packed[i]);
    }
    return offset;
}

} // namespace

std::vector<uint8_t> writeContainer(const std::vector<Section>& sections, const ContainerOptions& options) {
    std::vector<uint8_t> out;
    // Not released, so the sections stay as they are.
    emitContainer(const_cast<std::vector<Section>&>(sections), false, options,
                  [&](std::span<const uint8_t> bytes) { out.insert(out.end(), bytes.begin(), bytes.end()); });
    return out;
}

uint64_t writeContainerTo(std::vector<Section>&& sections, std::ostream& out, const ContainerOptions& options) {
    std::vector<Section> owned = std::move(sections);
    return emitContainer(owned, true, options, [&](std::span<const uint8_t> bytes) {
        out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        if (!out) throw Error("writing the .ssvdag file failed");
    });
}

std::vector<SectionSummary> summarizeContainer(std::span<const uint8_t> bytes, const std::string& sourceName) {
    std::vector<SectionSummary> out;
    const std::vector<Entry> entries = parseTable(bytes, sourceName, bytes.size());
    out.reserve(entries.size());
    for (const Entry& e : entries) out.push_back({SectionKind(e.kind), e.grid, e.codec == kCodecZstd, e.stored, e.raw});
    return out;
}

std::vector<Section> readContainer(std::span<const uint8_t> bytes, const std::string& sourceName, bool unknownKinds, const ReadLimits& limits) {
    const std::vector<Entry> entries = parseTable(bytes, sourceName, bytes.size());
    checkInflatedSize(entries, unknownKinds, limits, sourceName);
    std::vector<Section> sections;
    sections.reserve(entries.size());
    for (size_t i = 0; i < entries.size(); ++i) {
        const Entry& e = entries[i];
        const std::string what = sourceName + ": " + describe(i, e.kind, e.grid);
        if (!unknownKinds && isUnknownKind(e.kind)) {
            // Checked (its stored bytes), never inflated: a reader that does
            // not know the kind has no use for it, whatever it claims to hold.
            if (XXH3_64bits(bytes.data() + e.offset, e.stored) != e.checksum) throw Error(what + ": checksum mismatch, the file is corrupted");
            continue;
        }
        sections.push_back({SectionKind(e.kind), e.grid, restore(e, bytes.subspan(e.offset, e.stored), what)});
    }
    return sections;
}


namespace {

// The checked table of an open file: the header first, for the table's
// size, then header and table together.
std::vector<Entry> readTable(const InputFile& file, const std::string& path) {
    std::vector<uint8_t> head = file.read(0, std::min<uint64_t>(file.size, kHeaderBytes), path);
    if (head.size() == kHeaderBytes && std::memcmp(head.data(), kMagic, sizeof(kMagic)) == 0) {
        uint32_t count;
        std::memcpy(&count, head.data() + 12, 4);
        head = file.read(0, std::min<uint64_t>(file.size, kHeaderBytes + uint64_t(count) * kEntryBytes + kChecksumBytes), path);
    } else {
        head = file.read(0, std::min<uint64_t>(file.size, 352), path);  // enough to tell a NIfTI or DICOM file in the refusal
    }
    return parseTable(head, path, file.size);
}

} // namespace

std::vector<Section> readContainerFile(const std::string& path, bool unknownKinds, const ReadLimits& limits) {
    return readContainerFile(path, unknownKinds, limits, nullptr);
}

std::vector<Section> readContainerFile(const std::string& path, bool unknownKinds, const ReadLimits& limits, const SectionFilter& keep) {
    const InputFile file(path);
    std::vector<Entry> entries = readTable(file, path);
    std::vector<size_t> index(entries.size());  // each kept entry's place in the table, for the messages
    for (size_t i = 0; i < entries.size(); ++i) index[i] = i;
    if (keep) {
        size_t n = 0;
        for (size_t i = 0; i < entries.size(); ++i)
            if (keep(SectionKind(entries[i].kind), entries[i].grid)) {
                entries[n] = entries[i];
                index[n++] = i;
            }
        entries.resize(n);
        index.resize(n);
    }
    checkInflatedSize(entries, unknownKinds, limits, path);
    std::vector<Section> sections;
    sections.reserve(entries.size());
    for (size_t i = 0; i < entries.size(); ++i) {
        const Entry& e = entries[i];
        const std::string what = path + ": " + describe(index[i], e.kind, e.grid);
        std::vector<uint8_t> stored = file.read(e.offset, e.stored, path);
        if (stored.size() != e.stored) throw Error(what + ": the file was cut short while it was read");
        if (XXH3_64bits(stored.data(), stored.size()) != e.checksum) throw Error(what + ": checksum mismatch, the file is corrupted");
        if (!unknownKinds && isUnknownKind(e.kind)) continue;  // checked, never inflated
        if (e.codec == kCodecRaw) sections.push_back({SectionKind(e.kind), e.grid, std::move(stored)});  // no copy
        else sections.push_back({SectionKind(e.kind), e.grid, zstdInflateFrame(stored, e.raw, what)});
    }
    return sections;
}

std::vector<Section> storedSectionsOf(const std::string& path) {
    const InputFile file(path);
    std::vector<Section> sections;
    for (const Entry& e : readTable(file, path)) {
        Section s{SectionKind(e.kind), e.grid, {}};
        s.stored = std::make_shared<const StoredPayload>(StoredPayload{path, e.offset, e.stored, e.raw, e.checksum, e.codec == kCodecZstd});
        sections.push_back(std::move(s));
    }
    return sections;
}

struct StoredPayloadReader::Open {
    InputFile file;
};

StoredPayloadReader::StoredPayloadReader(const StoredPayload& payload) : payload_(payload), file_(new Open{InputFile(payload.path)}) {
    if (payload.zstd) throw Error(payload.path + ": internal error: a compressed section is read only whole");
}
StoredPayloadReader::~StoredPayloadReader() = default;

std::vector<uint8_t> StoredPayloadReader::read(uint64_t offset, uint64_t n) const {
    if (offset > payload_.storedBytes || n > payload_.storedBytes - offset)
        throw Error(payload_.path + ": corrupt (a read of " + num(n) + " bytes at " + num(offset) + " of a " + num(payload_.storedBytes) + "-byte section)");
    std::vector<uint8_t> bytes = file_->file.read(payload_.offset + offset, n, payload_.path);
    if (bytes.size() != n) throw Error(payload_.path + ": truncated (the file ends inside a section)");
    return bytes;
}

std::vector<uint8_t> readFileBytes(const std::string& path) {
    auto fail = [&](const std::string& why, int err) { throw Error(path + ": " + why + " (" + std::strerror(err) + ")"); };
    // O_NONBLOCK: opening a FIFO must not block (it is refused below).
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
        const int err = errno;
        if (err == ENOENT || err == ENOTDIR) throw Error(path + ": no such file");
        fail("cannot be opened for reading", err);
    }
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st{};
    if (::fstat(fd, &st) != 0) fail("cannot be read", errno);
    if (!S_ISREG(st.st_mode)) {
        throw Error(path + ": is " + fileKindName(st.st_mode) + ", not an .ssvdag file");  // a device could be read forever, a FIFO block
    }
    // The size the file has now; a file that shrinks while it is read ends early.
    std::vector<uint8_t> bytes(size_t(st.st_size));
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            fail("read error", errno);
        }
        if (n == 0) break;
        done += size_t(n);
    }
    bytes.resize(done);
    return bytes;
}

} // namespace vdbdag::format
