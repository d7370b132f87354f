// Sequence files: the frames of a simulation cache (smoke.0001.vdb ...) in
// one .ssvdag file. A Frames section lists each frame's number and how many
// grids it holds; the grids follow in frame order, each frame's sections as
// its own file would hold them, and a frame's .vdb file metadata is its
// FrameMetadata section (docs/FORMAT.md 4.3). A reader that predates
// sequences drops the kinds it does not know and sees every frame's grids
// as the grids of one file (or, where SameAs stands for sections, refuses
// the file: a grid lacks a required section).
//
// writeSequence gathers files encoded one frame at a time: their sections
// are copied as they are stored (never inflated or compressed again), so a
// sequence file is the same bytes however its frames were encoded
// (--threads, --memory-limit, mpirun), and building it takes the memory of
// its section table only.
#pragma once
#include <cstdint>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "src/format/SsvdagContainer.h"

namespace vdbdag::format {

struct FrameEntry {
    int64_t number = 0;
    uint32_t gridCount = 0;
};

// The Frames payload: u32 F, then per frame i64 number and u32 grid count.
std::vector<uint8_t> serializeFrames(std::span<const FrameEntry> frames);
// Checks: at least one frame, each with at least one grid, numbers strictly
// increasing, grid counts summing to `gridCount` (the FileInfo's), nothing after.
std::vector<FrameEntry> parseFrames(std::span<const uint8_t> payload, uint64_t gridCount, const std::string& what);

// SameAs (a grid's sections that hold the same bytes as an earlier grid's:
// a grid that does not change between frames is stored once): u32 n, then
// per section u32 kind and u32 the earlier grid. Checks: 1 <= n <= 32, each
// kind a grid's own (not FileInfo, Frames, FileMetadata, FrameMetadata or
// SameAs) and named once, each earlier grid below `grid`, nothing after.
struct SameAsEntry {
    SectionKind kind{};
    uint32_t grid = 0;  // the earlier grid holding the bytes
};
std::vector<uint8_t> serializeSameAs(std::span<const SameAsEntry> entries);
std::vector<SameAsEntry> parseSameAs(std::span<const uint8_t> payload, uint32_t grid, const std::string& what);

// A frame's own .ssvdag file and its number.
struct FramePart {
    int64_t number = 0;
    std::string path;
};
// Writes the sequence of `parts` (numbers strictly increasing) to `out`;
// returns the bytes written. Each part must be a file of one volume (not a
// sequence itself); its FileMetadata becomes the frame's FrameMetadata. A
// section whose stored bytes equal an earlier frame's section of the same
// kind (compared byte for byte) is not stored again: its grid's SameAs
// section names the earlier one.
uint64_t writeSequence(std::span<const FramePart> parts, std::ostream& out);

// The frames of the .ssvdag file at `path` (its Frames section; a file of
// one volume is one frame, numbered 0) and its grid count: the table and two
// small sections are read.
struct FrameList {
    std::vector<FrameEntry> frames;
    uint32_t gridCount = 0;
    bool sequence = false;       // the file has a Frames section
    std::vector<uint8_t> fileInfo;  // the FileInfo payload
};
FrameList readFrameList(const std::string& path);

// The grids [first, end) of frame `index` (a file of one volume: frame 0
// holds all `gridCount`); throws vdbdag::Error naming `what` past the last frame.
struct GridRange {
    uint32_t first = 0, end = 0;
};
GridRange frameGrids(std::span<const FrameEntry> frames, uint32_t gridCount, uint32_t index, const std::string& what);

} // namespace vdbdag::format
