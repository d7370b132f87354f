// NRRD headers (http://teem.sourceforge.net/nrrd/format.html): attached
// (.nrrd, samples after the blank line ending the header) and detached
// (.nhdr with "data file:"). Supported: dimension 3, the integer and float
// types of DenseVolume (every NRRD alias: "short", "uint16_t", ...),
// encodings raw and gzip, "endian", "sizes", "spacings" or "space
// directions", "space origin", "byte skip" (-1 = data at the end of a raw
// file) and "line skip". World coordinates are those of the file's "space"
// (LPS stays LPS). 4-D: a leading axis of 3 components (vector, RGB) or a
// last axis of volumes (a time series: one grid per volume, as for NIfTI).
// Anything else that changes the meaning of the samples (block/int64 types,
// ascii/bzip2 encodings, data file lists, other non-spatial axes) is refused
// with a one-line error naming the header.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge {

// `volume`: which volume of a 4-D series (its last axis non-spatial),
// 0-based; the grid is then named NAME_tN and DenseVolume::volumeIndex /
// volumeCount say so. Ignored for 3-D files and vector files.
DenseVolume readNrrdHeader(const std::string& path, std::optional<int64_t> volume = std::nullopt);

} // namespace vdbdag::bridge
