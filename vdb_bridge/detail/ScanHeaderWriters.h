// The header of each scan format exportDense writes, from the layout of
// the samples that follow it: NRRD (attached or detached), MetaImage and
// NIfTI-1/NIfTI-2 single files. Pure text and bytes; no samples, no files.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "vdb_bridge/detail/ScanLayout.h"

namespace vdbdag::bridge::detail {

std::string nrrdHeader(const ScanLayout& l, const std::string& dataFile);
std::string metaImageHeader(const ScanLayout& l, const std::string& dataFile);
// The header, its extensions and the padding up to vox_offset: the bytes
// before the first sample. `notes` gets what could not be written back.
// Throws vdbdag::Error naming `path` when the layout does not fit NIfTI.
std::vector<uint8_t> niftiHeader(const ScanLayout& l, const std::string& path, std::vector<std::string>* notes = nullptr);

} // namespace vdbdag::bridge::detail
