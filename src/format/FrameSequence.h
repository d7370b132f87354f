// Sequence files: the frames of a simulation cache (smoke.0001.vdb ...) in
// one .ssvdag file. A Frames section lists each frame's number and how many
// grids it holds; the grids follow in frame order, each frame's sections as
// its own file would hold them, and a frame's .vdb file metadata is its
// FrameMetadata section (docs/FORMAT.md 4.3). A reader that predates
// sequences drops the two kinds it does not know and sees every frame's
// grids as the grids of one file.
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

// A frame's own .ssvdag file and its number.
struct FramePart {
    int64_t number = 0;
    std::string path;
};
// Writes the sequence of `parts` (numbers strictly increasing) to `out`;
// returns the bytes written. Each part must be a file of one volume (not a
// sequence itself); its FileMetadata becomes the frame's FrameMetadata.
uint64_t writeSequence(std::span<const FramePart> parts, std::ostream& out);

// The frames of the .ssvdag file at `path` (its Frames section; a file of
// one volume is one frame, numbered 0) and its grid count: the table and two
// small sections are read.
struct FrameList {
    std::vector<FrameEntry> frames;
    uint32_t gridCount = 0;
    bool sequence = false;  // the file has a Frames section
};
FrameList readFrameList(const std::string& path);

} // namespace vdbdag::format
