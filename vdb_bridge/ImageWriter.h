// Writes a rendered frame: .png (8-bit sRGB colour) by vdbdag itself
// (PngFile.h: zlib only, no OpenImageIO mapped); .exr (float R, G, B, A,
// depth Z and world normal N.x, N.y, N.z) or any other extension
// OpenImageIO knows (.jpg, .tif: colour only) through OpenImageIO, in
// libvdbdag_images.so, loaded at the first such picture. Atomic: the file
// appears complete or not at all, every write checked (a full disk).
#pragma once
#include <string>

#include "src/trace/Image.h"

namespace vdbdag::bridge {

void writeImage(const std::string& path, const trace::Image& image);

} // namespace vdbdag::bridge
