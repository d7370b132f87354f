// The .ssvdag container: magic, format version, a table of typed sections
// (each with its stored size, raw size, codec and xxh3-64 checksum), then the
// section payloads; little-endian throughout; zstd at rest by default.
// The reader validates every size, offset and checksum before it uses it, and
// never allocates more than the file's size can justify. The byte layout is
// documented in SsvdagContainer.cpp beside the code that writes it.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <functional>
#include <iosfwd>
#include <memory>
#include <vector>

#include "src/format/ReadLimits.h"
#include "src/util/ScratchFile.h"

namespace vdbdag::format {

// The container versions (the u32 after the magic). A file is written as
// version 1 unless it holds a section that an older reader must not skip
// (one whose absence would change what that reader decodes): then as
// version 2, which readers before it refuse. This build reads both.
inline constexpr uint32_t kFormatVersion = 1;
inline constexpr uint32_t kLatestFormatVersion = 3;

// Section kinds. A file holds a section only when the scene needs it
// (../shared/DESIGN.md invariant 3). Unknown kinds are rejected by readers that need
// them and skipped by those that do not.
enum class SectionKind : uint32_t {
    FileInfo = 1,       // whole-file facts (grid count, writer version)
    GridInfo = 2,       // per grid: name, class, value type, origin, depth, affine
    VdbDescriptor = 3,  // per grid: OpenVDB stream of an empty copy of the grid (opaque)
    DagLevels = 4,      // per grid: level table of the compact encoding
    DagInner = 5,       // per grid: inner-node 16-bit words
    DagLeaves = 6,      // per grid: 64-bit 4^3 leaves
    DagStats = 7,       // per grid: per-level SVO / SVDAG / SSVDAG node counts
    Values = 8,         // per grid: active values in attribute order (byte-shuffled at rest)
    InactiveLevels = 9, // per grid: the DAG of inactive voxels/tiles whose value is not the background
    InactiveInner = 10,
    InactiveLeaves = 11,
    InactiveValues = 12,
    ValueErrors = 13,   // per grid, lossy encodings only: the tolerance and the measured errors
    ColourErrors = 14,  // per colour grid encoded with --colour-bits: bits and the measured colour errors
    Normals = 15,       // per grid, only with --normals: k-bit ONV codes in attribute order (palette channel) + angular errors
    ValueWindows = 16,          // per grid: active values in attribute order, palette-coded and zstd'd in fixed windows (ValueWindows.h)
    InactiveValueWindows = 17,  // the same for the inactive layer
    PredictedWindows = 18,          // per grid, int32/int64: active values in brick-aligned windows, each palette- or brick-predicted-coded (PredictedWindows.h)
    InactivePredictedWindows = 19,  // the same for the inactive layer
    PredictedValues = 20,          // per grid: integer active values predicted in attribute order (instead of Values; written before PredictedWindows, still read)
    InactivePredictedValues = 21,  // the same for the inactive layer (instead of InactiveValues)
    FileMetadata = 22,  // file-level: the .vdb file's own metadata (opaque, vdb_bridge); absent when it has none
    Frames = 23,         // file-level, sequence files only: each frame's number and grid count (FrameSequence.h)
    FrameMetadata = 24,  // sequence files: a frame's .vdb file metadata (as FileMetadata); grid = the frame's first grid
    SameAs = 25,         // sequence files: this grid's section of a kind holds the bytes of an earlier grid's (a grid that does not change between frames)
    Summary = 26,        // per grid: what `info` prints that the DAG and values would otherwise give (index box, solid nodes, value range)
    InactiveSignedFill = 27,  // per grid (version 2): the inactive layer is OpenVDB's signed flood fill of the active values, made again by the reader (no Inactive* sections)
    ValueReference = 28,      // per grid (version 3): its active predicted windows of codings 21 and 22 read an earlier grid's same windows (a 4-D scan's previous volume)
};

const char* sectionKindName(SectionKind kind);  // "unknown" for a kind this build does not know
bool isKnownKind(SectionKind kind);
// Sections whose payload is compressed already (the writer stores them raw).
bool isPrecompressed(SectionKind kind);

struct Section {
    SectionKind kind{};
    uint32_t grid = 0;          // grid index the section belongs to (0 for file-level)
    std::vector<uint8_t> data;  // raw (uncompressed) payload
    // For the writer only: a precompressed payload too large to hold (the
    // value windows of a grid encoded in bounded memory) is this whole
    // scratch file instead of `data`, copied into the file as it is.
    std::shared_ptr<const ScratchFile> spilled = nullptr;
    // For the writer only: a section copied as it is stored in another
    // .ssvdag file (storedSectionsOf), never inflated or compressed again;
    // its checksum is checked as it is copied.
    std::shared_ptr<const struct StoredPayload> stored = nullptr;
};

// The version a file of these sections is written as (kFormatVersion; 2
// with an InactiveSignedFill section; 3 with a ValueReference section).
uint32_t formatVersionOf(std::span<const Section> sections);

// Where a section lies in an .ssvdag file, as its table says.
struct StoredPayload {
    std::string path;
    uint64_t offset = 0, storedBytes = 0, rawBytes = 0, checksum = 0;
    bool zstd = false;
};

// What a reader learns about a section without decoding it (for `info`).
struct SectionSummary {
    SectionKind kind{};
    uint32_t grid = 0;
    bool compressed = false;
    uint64_t storedBytes = 0;  // bytes in the file
    uint64_t rawBytes = 0;     // bytes once restored in memory
};

struct ContainerOptions {
    bool compress = true;  // zstd each section; kept raw if zstd does not shrink it
    int zstdLevel = 9;
    // parallel(n, body) runs body(0 .. n-1) in any order, on any threads (an
    // encoder's pool: util::tbbParallelFor): the sections are then compressed
    // side by side, each alone, so the bytes are those of one thread. Empty:
    // one after another (the reader library links no pool).
    std::function<void(size_t n, const std::function<void(size_t)>& body)> parallel;
};

// Bytes a section of `raw` payload takes in the file (its zstd frame as the
// writer makes it, or the raw bytes when zstd does not shrink them).
uint64_t storedSectionBytes(std::span<const uint8_t> raw, const ContainerOptions& options = {});

// Serialises sections into the container bytes.
std::vector<uint8_t> writeContainer(const std::vector<Section>& sections, const ContainerOptions& options = {});
// The same bytes, written to `out` section by section: each section's raw
// bytes are released once compressed and its payload once written, so the
// file is never whole in memory twice. Returns the bytes written; throws
// vdbdag::Error when the stream fails.
uint64_t writeContainerTo(std::vector<Section>&& sections, std::ostream& out, const ContainerOptions& options = {});

// Parses and validates container bytes; throws vdbdag::Error with a one-line
// message starting with `sourceName` on any truncation, corruption, checksum
// mismatch or implausible size. With `unknownKinds` false, sections of kinds
// this reader does not know are checksum-checked and dropped, never inflated
// (what the scene readers do: such a section may claim gigabytes). The
// sections' declared raw sizes together must lie within limits.maxMemory,
// checked before any is inflated.
std::vector<Section> readContainer(std::span<const uint8_t> bytes, const std::string& sourceName, bool unknownKinds = true,
                                   const ReadLimits& limits = {});

// Validates the header and table only (no payload decompression) and returns
// the section summaries.
std::vector<SectionSummary> summarizeContainer(std::span<const uint8_t> bytes, const std::string& sourceName);

// The sections of the .ssvdag file at `path` as it stores them (header and
// table checked as readContainer checks them; the payloads are checked when
// written): for a writer that copies them into another file unchanged.
std::vector<Section> storedSectionsOf(const std::string& path);

// Parts of a section's payload as its file stores it (codec raw: the
// payload's own bytes), read where they lie, never the whole section: what
// `info` reads of a large section (attributes::predictedWindowCodings).
// Not checked against the section's checksum (that covers the whole).
class StoredPayloadReader {
public:
    explicit StoredPayloadReader(const StoredPayload& payload);
    ~StoredPayloadReader();
    uint64_t size() const { return payload_.storedBytes; }
    // `n` bytes from `offset` of the payload; throws Error naming the file
    // when they lie outside it or the file ends before them.
    std::vector<uint8_t> read(uint64_t offset, uint64_t n) const;

private:
    StoredPayload payload_;
    struct Open;
    std::unique_ptr<Open> file_;
};

// Reads a whole file into memory (throws Error naming the file if missing or
// unreadable).
std::vector<uint8_t> readFileBytes(const std::string& path);
// readContainer of the file at `path`, read section by section: memory
// holds the sections, never the file as well.
std::vector<Section> readContainerFile(const std::string& path, bool unknownKinds = true, const ReadLimits& limits = {});
// The same, keeping only the sections `keep(kind, grid)` accepts: the others
// are neither read nor weighed against the limits (one frame of a sequence).
using SectionFilter = std::function<bool(SectionKind kind, uint32_t grid)>;
std::vector<Section> readContainerFile(const std::string& path, bool unknownKinds, const ReadLimits& limits, const SectionFilter& keep);

} // namespace vdbdag::format
