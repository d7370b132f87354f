// `vdbdag decode` of one .ssvdag file (or one frame of a sequence file) as
// a library call: to a .vdb, a NanoVDB .nvdb, or a dense scan file (.nrrd,
// .nhdr, .mha, .mhd, .nii, .nii.gz, .raw) with the scan's own sample type,
// extent and patient space (vdb_bridge/DenseExport.h), written atomically.
// A scan output is written cube by cube from the DAG where the grid allows
// it, never the whole grid in memory. cli/DecodeCommand.cpp parses options
// into a DecodeRequest and prints the result.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "src/format/ReadLimits.h"

namespace vdbdag::app {

struct DecodeRequest {
    std::string input, output;
    std::string grid;               // a scan output: the grid to write (empty: the file's only grid, or a 4-D scan's volumes)
    std::optional<uint32_t> frame;  // a sequence file: the frame (its index) to write
    bool force = false;             // replace an existing output (never the input, a link or a device)
    bool storedValues = false;      // a rescaled scan to NRRD/MetaImage/raw: the stored integers, the rescale as key/value pairs
    format::ReadLimits limits;      // what the file may make the decode hold (its valueCopies is set here)
};

struct DecodeResult {
    nlohmann::json report;           // as `decode --json` prints it
    std::vector<std::string> notes;  // what changed on the way out (a value written otherwise than stored), one line each
};

// Throws vdbdag::Error naming the file on a refusal; nothing is written then.
DecodeResult decodeFile(const DecodeRequest& request);

// `vdbdag decode IN -o OUT [--frames SEL]` whole: a file of one volume to
// the output; a sequence file's frames (`frames`: "12", "10-20",
// "1,5,9-12"; empty: all) each to the output with its number in the frame
// token (out.####.vdb), or the one chosen to the output itself
// (FrameJobs.h). request.frame is ignored. Every output is checked before
// any is written; `onFile` sees each one's result as it is written (the
// report of a sequence's frame carries "frame": its number). Returns the
// report: one volume's object, or an array of the frames' reports.
nlohmann::json decodeFiles(const DecodeRequest& request, const std::string& frames,
                           const std::function<void(const std::string& output, const DecodeResult&)>& onFile = {});

} // namespace vdbdag::app
