// Frame-numbered file names, as VFX caches are named: smoke.0042.vdb.
// A pattern holds one frame token, in the spellings of the field's tools:
//   ####      (Houdini, Nuke, vdb_view: the number zero-padded to 4 digits;
//              one # per digit)
//   %04d %d   (printf, ffmpeg, ParaView)
//   $F4 $F    (Houdini's frame variable, padded to 4 digits; $F unpadded)
// A negative frame is written with its sign before the padding: -001.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace vdbdag {

struct FrameFile {
    int64_t number = 0;
    std::string path;
};

// Whether `text`'s file name holds a frame token (the folder part may not).
bool isFramePattern(const std::string& text);
// The file name of frame `number`: the token replaced by the padded number.
std::string framePath(const std::string& pattern, int64_t number);
// The files that exist and match the pattern exactly (the name framePath
// gives for their number), by frame number; none is an empty list.
std::vector<FrameFile> expandFramePattern(const std::string& pattern);
// The pattern's name with the token and the separator before it taken
// out: "out/smoke.####.vdb" -> "out/smoke.vdb".
std::string withoutFrameToken(const std::string& pattern);
// The frame number of a file named as a cache frame: the last run of
// digits in its name before the extension(s) (smoke.0042.vdb -> 42,
// smoke_12.nii.gz -> 12); none without digits there.
std::optional<int64_t> frameNumberOf(const std::string& path);
// Frames from a list of files: numbered by their names when every name has
// a number and no two share one (sorted by it), else 1..N in the order given.
std::vector<FrameFile> framesOfList(const std::vector<std::string>& paths);

// A frame selection: "12", "10-20", "1,5,9-12" (inclusive ranges).
struct FrameSelection {
    std::vector<std::pair<int64_t, int64_t>> ranges;
    bool contains(int64_t frame) const;
};
// Throws vdbdag::Error naming `text` when it is not a selection.
FrameSelection parseFrameSelection(const std::string& text);

} // namespace vdbdag
