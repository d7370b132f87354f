// Frames of a cache into one sequence file (format/FrameSequence.h), as a
// library call: each frame encoded alone by the caller (every option
// applies: the same bytes as its own file) into a temporary folder beside
// the output (or in the scratch folder), then the frame files gathered into
// the output section by section, and the folder removed. Under mpirun the
// frames are spread over the team's processes, each frame encoded by one
// process alone, into the first process's folder (a shared file system, as
// for the input); the first process then gathers them and writes.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "src/pipeline/CubeTeam.h"
#include "src/util/FramePattern.h"

namespace vdbdag::app {

struct SequenceRequest {
    std::vector<FrameFile> frames;  // in order, each with its number
    std::string output;             // the .ssvdag sequence file
    std::string described;          // the input as the report names it (a pattern, a folder, "3 files")
    std::string scratch;            // the frames' folder goes here (empty: beside the output)
    bool force = false;             // replace an existing output (never an input, a link or a device)
};

// Encodes frame `index` (its input file) into `output` on this process
// alone, reporting its progress 0..1 through `onProgress`, and returns its
// report (as `encode --json` prints it).
using EncodeFrame = std::function<nlohmann::json(size_t index, const std::string& input, const std::string& output,
                                                 const std::function<void(double)>& onProgress)>;

struct SequenceResult {
    bool written = false;  // false on a process of the team other than the first
    nlohmann::json report;  // the sequence's, with each frame's under "per_frame"
};

// Throws vdbdag::Error on a refused output or a failed frame; nothing is
// written then (the output appears whole or not at all). Progress on a
// terminal, the frames' own lines silent.
SequenceResult encodeSequence(const SequenceRequest& request, pipeline::CubeTeam& team, const EncodeFrame& encodeFrame);

} // namespace vdbdag::app
