// NRRD headers (http://teem.sourceforge.net/nrrd/format.html): attached
// (.nrrd, samples after the blank line ending the header) and detached
// (.nhdr with "data file:"). Supported: dimension 3, the integer and float
// types of DenseVolume (every NRRD alias: "short", "uint16_t", ...),
// encodings raw and gzip, "endian", "sizes", "spacings" or "space
// directions", "space origin", "byte skip" (-1 = data at the end of a raw
// file) and "line skip". World coordinates are those of the file's "space"
// (LPS stays LPS). Anything else that changes the meaning of the samples
// (block/int64 types, ascii/bzip2 encodings, data file lists, non-spatial
// axes) is refused with a one-line error naming the header.
#pragma once
#include <string>

#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge {

DenseVolume readNrrdHeader(const std::string& path);

} // namespace vdbdag::bridge
