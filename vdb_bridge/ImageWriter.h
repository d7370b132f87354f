// Writes a rendered frame through OpenImageIO (in libvdbdag_images.so,
// loaded at the first picture): .png (8-bit sRGB colour), .exr (float R, G,
// B, A, depth Z and world normal N.x, N.y, N.z), or any other extension
// OpenImageIO knows (.jpg, .tif: colour only). Atomic: the file appears
// complete or not at all.
#pragma once
#include <string>

#include "src/trace/Image.h"

namespace vdbdag::bridge {

void writeImage(const std::string& path, const trace::Image& image);

} // namespace vdbdag::bridge
