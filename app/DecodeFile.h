// `vdbdag decode` of one .ssvdag file (or one frame of a sequence file) as
// a library call: to a .vdb, a NanoVDB .nvdb, or a dense scan file (.nrrd,
// .nhdr, .mha, .mhd, .nii, .nii.gz, .raw) with the scan's own sample type,
// extent and patient space (vdb_bridge/DenseExport.h), written atomically.
// A scan output is written cube by cube from the DAG where the grid allows
// it, never the whole grid in memory. cli/DecodeCommand.cpp parses options
// into a DecodeRequest and prints the result.
#pragma once
#include <cstdint>
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

} // namespace vdbdag::app
