// What an output path may be, checked before any work is done: the rules of
// zstd and xz. The extension names the format (and must be one the command
// writes); the output is never one of the command's inputs (same file
// through links, hard links or another spelling of the path, or the data file
// behind a header); an existing file is replaced only with --force, and never
// when it is read-only, a link, a device, a FIFO, a socket or a folder.
#pragma once
#include <string>
#include <vector>

namespace vdbdag {

struct OutputRules {
    std::vector<std::string> extensions;  // lower-case with the dot, e.g. {".vtu", ".vti", ".vtm"}
    std::string command;                  // for messages: "encode"
    bool force = false;                   // -f / --force: replace an existing regular file
};

// Throws vdbdag::Error ("OUTPUT: why") unless `output` may be written.
void checkOutputPath(const std::string& output, const std::vector<std::string>& inputs, const OutputRules& rules);

// The lower-case extension of `path` with its dot ("" if none).
std::string lowerExtension(const std::string& path);

} // namespace vdbdag
