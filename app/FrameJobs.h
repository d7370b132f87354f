// Which frames of an input a command writes, and to which files (decode,
// render): a file of one volume goes whole to -o; a sequence file's frames
// chosen by the frame option each to -o with its number in the frame token
// (out.####.vdb), or the one chosen to -o itself.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "src/format/FrameSequence.h"

namespace vdbdag::app {

struct FrameJob {
    std::optional<uint32_t> index;  // into the file's frames; none: the file whole
    int64_t number = 0;
    std::string output;
};

struct FrameRequest {
    std::string input, output;
    std::string selection;  // the frame option's text ("" : every frame)
    std::string option;     // its name, "--frames"
    std::string noun;       // what -o names: "file", "image"
    std::string several;    // how to write several frames, when -o has no token
};

// `list`: the input's frames (none: not an .ssvdag). Throws vdbdag::Error
// with one line for a selection of no frame, several frames to one output,
// a frame option or token for a file of one volume.
std::vector<FrameJob> frameJobs(const FrameRequest& request, const std::optional<format::FrameList>& list);

} // namespace vdbdag::app
