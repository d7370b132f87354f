// An 8-bit RGB PNG (ISO/IEC 15948) written by vdbdag with zlib alone: the
// rendered frames' format, without OpenImageIO and the hundreds of libraries
// it maps (a renderer under a small memory cap, issue 38 #9). IHDR, sRGB
// (perceptual intent), IDAT chunks of rows each filtered as libpng's default
// heuristic does (the filter whose bytes sum least as signed values), IEND.
#pragma once
#include <cstdint>
#include <iosfwd>
#include <span>
#include <vector>

namespace vdbdag::bridge {

// Writes the file for `width` x `height` pixels of `rgb` (3 bytes each,
// row-major, row 0 at the top) to `out` as it is made, row by row.
void writePng(std::ostream& out, int width, int height, std::span<const uint8_t> rgb);
// The same file's bytes.
std::vector<uint8_t> encodePng(int width, int height, std::span<const uint8_t> rgb);

} // namespace vdbdag::bridge
