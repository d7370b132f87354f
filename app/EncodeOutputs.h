// Where `vdbdag encode` writes and what it reads as a sequence, for the
// command line and other programs: an input's default output (IN.ssvdag
// beside it), a folder of cache frames, and the outputs of several inputs
// encoded one file each.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace vdbdag::app {

// IN.ssvdag beside the input: its name without its extension (.nii.gz,
// .raw.gz and the like count as one), a folder's name for a folder. Throws
// vdbdag::Error when the input gives no name.
std::string defaultOutputFor(const std::string& input);

// A folder holding .vdb or .nvdb files and nothing else (hidden files
// aside): the frames of a cache, sorted by name. Otherwise nothing.
std::optional<std::vector<std::string>> cacheFrameFiles(const std::string& folder);

// The output of each of several inputs encoded one file each: in `folder`
// (made when missing; refused when it names a file or ends in .ssvdag) or,
// when empty, beside each input, as IN.ssvdag. Throws vdbdag::Error when
// two inputs would write the same file.
std::vector<std::string> outputsForEach(const std::vector<std::string>& inputs, const std::string& folder);

} // namespace vdbdag::app
