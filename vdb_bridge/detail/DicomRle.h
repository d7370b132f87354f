// RLE Lossless (transfer syntax 1.2.840.10008.1.2.5, DICOM PS3.5 annex G)
// pixel data as GDCM 3.0.21's RLECodec decodes it. Its DecodeByStreams
// trusts the RLE header: a segment count over 15 indexes past the header's
// 15 offsets (a read out of bounds, SIGSEGV: found by fuzz_scan_headers),
// a count of 0 divides by zero, and a count that does not divide the frame
// aborts in its byte reordering. So each frame's bytes (GDCM's view: the
// one fragment of a frame of a multi-frame file; all fragments end to end
// for a single frame) are checked here first, by decoding their runs
// without output.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace gdcm {
class File;
}

namespace vdbdag::bridge::detail {

// "" when `frame` (its `size` bytes) holds an RLE header of `segments`
// segments (DICOM's: one per byte of a sample times samples per pixel),
// the first at byte 64, each starting inside the frame after the one
// before, whose runs decode to exactly `frameBytes / segments` bytes each
// from bytes inside the frame; else what is wrong.
std::string rleFrameProblem(const uint8_t* frame, size_t size, unsigned segments, uint64_t frameBytes);

inline constexpr const char* kRleSyntax = "1.2.840.10008.1.2.5";

// "" when the RLE pixel data of `file` (read whole by gdcm::Reader, not yet
// by its image reader, which decodes them) are safe for GDCM to decode:
// each frame passes rleFrameProblem in the pixel format and frame count
// GDCM's image reader takes from the header; else what is wrong.
std::string rleProblem(const gdcm::File& file);

} // namespace vdbdag::bridge::detail
