// The .ssvdag container (see SsvdagContainer.h). Byte layout, little-endian:
//
//   offset  size  field
//   0       8     magic "\x89SSVDAG\n" (a high byte and a newline, like PNG's,
//                 so text-mode transfers and 7-bit channels are detected)
//   8       4     u32 format version (kFormatVersion)
//   12      4     u32 section count N
//   16      48*N  section table, one entry per section:
//                   u32 kind, u32 grid, u32 codec (0 raw, 1 zstd), u32 reserved (0),
//                   u64 payload offset (from the start of the file),
//                   u64 stored size (bytes in the file), u64 raw size (bytes restored),
//                   u64 xxh3-64 of the stored bytes
//   16+48N  8     u64 xxh3-64 of bytes [0, 16+48N): header and table
//   ...           payloads, in table order, without gaps
//
// The reader checks, in this order and before using any of it: the magic,
// the version, that the table fits the file, the table checksum, every
// payload's bounds (overflow-safe) and that payloads neither overlap nor
// leave gaps, each payload's checksum, the raw size against what the codec
// can produce from the stored size, and finally that zstd restores exactly
// the raw size. So a truncated or corrupted file gets a one-line error, and
// no allocation exceeds what the file's own size justifies.
#include "src/format/SsvdagContainer.h"

#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <sys/stat.h>

#include <xxhash.h>
#include <zstd.h>

#include "src/format/ByteIO.h"
#include "src/util/Error.h"

namespace vdbdag::format {
namespace {

static_assert(std::endian::native == std::endian::little, "the .ssvdag reader and writer assume a little-endian host");

constexpr uint8_t kMagic[8] = {0x89, 'S', 'S', 'V', 'D', 'A', 'G', '\n'};
constexpr uint32_t kFormatVersion = 1;
constexpr size_t kHeaderBytes = 16;
constexpr size_t kEntryBytes = 48;
constexpr uint32_t kCodecRaw = 0, kCodecZstd = 1;
// zstd cannot expand data by more than this factor (RLE blocks of 128 KiB
// cost a few bytes each); a claim beyond it is a corrupt table.
constexpr uint64_t kMaxZstdRatio = uint64_t(1) << 16;

struct Entry {
    uint32_t kind, grid, codec, reserved;
    uint64_t offset, stored, raw, checksum;
};

struct ParsedTable {
    std::vector<Entry> entries;
};

ParsedTable parseTable(std::span<const uint8_t> bytes, const std::string& name) {
    auto fail = [&](const std::string& why) -> void { throw Error(name + ": " + why); };
    if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
        fail("not an .ssvdag file (bad magic)");
    if (bytes.size() < kHeaderBytes) fail("truncated: the header needs " + std::to_string(kHeaderBytes) + " bytes, the file has " + std::to_string(bytes.size()));
    ByteReader header(bytes.subspan(8, 8), name);
    const uint32_t version = header.get<uint32_t>();
    const uint32_t count = header.get<uint32_t>();
    if (version != kFormatVersion)
        fail("unsupported format version " + std::to_string(version) + " (this vdbdag reads version " + std::to_string(kFormatVersion) + ")");
    const uint64_t tableEnd = kHeaderBytes + uint64_t(count) * kEntryBytes;
    if (tableEnd + 8 > bytes.size())
        fail("truncated: the section table of " + std::to_string(count) + " sections needs " + std::to_string(tableEnd + 8) + " bytes, the file has " + std::to_string(bytes.size()));
    ByteReader tail(bytes.subspan(tableEnd, 8), name);
    if (tail.get<uint64_t>() != XXH3_64bits(bytes.data(), tableEnd)) fail("checksum mismatch in the section table: the file is corrupted");

    ParsedTable table;
    ByteReader r(bytes.subspan(kHeaderBytes, tableEnd - kHeaderBytes), name);
    uint64_t expectedOffset = tableEnd + 8;
    for (uint32_t i = 0; i < count; ++i) {
        Entry e{r.get<uint32_t>(), r.get<uint32_t>(), r.get<uint32_t>(), r.get<uint32_t>(),
                r.get<uint64_t>(), r.get<uint64_t>(), r.get<uint64_t>(), r.get<uint64_t>()};
        const std::string what = "section " + std::to_string(i) + " ('" + sectionKindName(SectionKind(e.kind)) + "' of grid " + std::to_string(e.grid) + ")";
        if (e.codec != kCodecRaw && e.codec != kCodecZstd) fail(what + " has unknown codec " + std::to_string(e.codec));
        if (e.reserved != 0) fail(what + " has a non-zero reserved field");
        if (e.offset != expectedOffset) fail(what + " starts at byte " + std::to_string(e.offset) + ", expected " + std::to_string(expectedOffset));
        if (e.stored > bytes.size() || e.offset > bytes.size() - e.stored)
            fail("truncated: " + what + " ends past byte " + std::to_string(bytes.size()) + ", the end of the file");
        if (e.codec == kCodecRaw && e.raw != e.stored) fail(what + " claims " + std::to_string(e.raw) + " raw bytes for " + std::to_string(e.stored) + " stored raw bytes");
        if (e.codec == kCodecZstd && e.raw > e.stored * kMaxZstdRatio + 4096)
            fail(what + " claims " + std::to_string(e.raw) + " bytes from " + std::to_string(e.stored) + " compressed bytes, which zstd cannot produce");
        expectedOffset = e.offset + e.stored;
        table.entries.push_back(e);
    }
    if (expectedOffset != bytes.size()) fail(std::to_string(bytes.size() - expectedOffset) + " unexpected bytes after the last section");
    return table;
}

} // namespace

const char* sectionKindName(SectionKind kind) {
    switch (kind) {
        case SectionKind::FileInfo: return "FileInfo";
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
    }
    return "unknown";
}

std::vector<uint8_t> writeContainer(const std::vector<Section>& sections, const ContainerOptions& options) {
    std::vector<std::vector<uint8_t>> stored(sections.size());
    std::vector<uint32_t> codec(sections.size(), kCodecRaw);
    for (size_t i = 0; i < sections.size(); ++i) {
        const auto& data = sections[i].data;
        if (options.compress && data.size() > 64) {
            // Large sections (value channels) use a faster level on two
            // threads: level 9 on 100 MB would dominate the encode time.
            std::vector<uint8_t> packed(ZSTD_compressBound(data.size()));
            ZSTD_CCtx* cctx = ZSTD_createCCtx();
            const bool large = data.size() > (size_t(4) << 20);
            ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, large ? std::min(options.zstdLevel, 3) : options.zstdLevel);
            ZSTD_CCtx_setParameter(cctx, ZSTD_c_contentSizeFlag, 1);
            if (large) ZSTD_CCtx_setParameter(cctx, ZSTD_c_nbWorkers, 2);  // ignored if libzstd lacks threads
            const size_t n = ZSTD_compress2(cctx, packed.data(), packed.size(), data.data(), data.size());
            ZSTD_freeCCtx(cctx);
            if (ZSTD_isError(n)) throw Error(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
            if (n < data.size()) {
                packed.resize(n);
                stored[i] = std::move(packed);
                codec[i] = kCodecZstd;
                continue;
            }
        }
        stored[i] = data;
    }
    ByteWriter w;
    w.putBytes(std::span<const uint8_t>(kMagic, sizeof(kMagic)));
    w.put<uint32_t>(kFormatVersion);
    w.put<uint32_t>(uint32_t(sections.size()));
    uint64_t offset = kHeaderBytes + sections.size() * kEntryBytes + 8;
    for (size_t i = 0; i < sections.size(); ++i) {
        w.put<uint32_t>(uint32_t(sections[i].kind));
        w.put<uint32_t>(sections[i].grid);
        w.put<uint32_t>(codec[i]);
        w.put<uint32_t>(0);
        w.put<uint64_t>(offset);
        w.put<uint64_t>(stored[i].size());
        w.put<uint64_t>(sections[i].data.size());
        w.put<uint64_t>(XXH3_64bits(stored[i].data(), stored[i].size()));
        offset += stored[i].size();
    }
    w.put<uint64_t>(XXH3_64bits(w.bytes().data(), w.bytes().size()));
    for (const auto& s : stored) w.putBytes(s);
    return w.take();
}

std::vector<SectionSummary> summarizeContainer(std::span<const uint8_t> bytes, const std::string& sourceName) {
    std::vector<SectionSummary> out;
    for (const Entry& e : parseTable(bytes, sourceName).entries)
        out.push_back({SectionKind(e.kind), e.grid, e.codec == kCodecZstd, e.stored, e.raw});
    return out;
}

std::vector<Section> readContainer(std::span<const uint8_t> bytes, const std::string& sourceName) {
    const ParsedTable table = parseTable(bytes, sourceName);
    std::vector<Section> sections;
    sections.reserve(table.entries.size());
    for (size_t i = 0; i < table.entries.size(); ++i) {
        const Entry& e = table.entries[i];
        const std::string what = sourceName + ": section " + std::to_string(i) + " ('" + sectionKindName(SectionKind(e.kind)) + "' of grid " + std::to_string(e.grid) + ")";
        const uint8_t* payload = bytes.data() + e.offset;
        if (XXH3_64bits(payload, e.stored) != e.checksum) throw Error(what + ": checksum mismatch, the file is corrupted");
        Section s{SectionKind(e.kind), e.grid, {}};
        if (e.codec == kCodecRaw) {
            s.data.assign(payload, payload + e.stored);
        } else {
            const unsigned long long frameSize = ZSTD_getFrameContentSize(payload, e.stored);
            if (frameSize == ZSTD_CONTENTSIZE_ERROR || frameSize == ZSTD_CONTENTSIZE_UNKNOWN || frameSize != e.raw)
                throw Error(what + ": the zstd frame does not declare the expected " + std::to_string(e.raw) + " bytes");
            s.data.resize(e.raw);
            const size_t n = ZSTD_decompress(s.data.data(), s.data.size(), payload, e.stored);
            if (ZSTD_isError(n) || n != e.raw) throw Error(what + ": zstd data is corrupted");
        }
        sections.push_back(std::move(s));
    }
    return sections;
}

std::vector<uint8_t> readFileBytes(const std::string& path) {
    struct stat st{};
    if (stat(path.c_str(), &st) != 0) throw Error(path + ": no such file");
    if (S_ISDIR(st.st_mode)) throw Error(path + ": is a directory, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot be opened for reading");
    std::vector<uint8_t> bytes(size_t(st.st_size));
    if (!bytes.empty() && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size())))
        throw Error(path + ": read error");
    return bytes;
}

} // namespace vdbdag::format
