// The entry points of libvdbdag_images.so, the one part of vdbdag that
// links OpenImageIO. OpenImageIO brings OpenCV, GDAL, libavcodec and some
// 200 other libraries (89 MB resident, most of a call's start-up), so only
// the commands that write pictures load it, at first use
// (vdb_bridge/detail/ImageModuleLoader). Same build, same compiler: the
// functions take C++ types; C linkage only fixes their names for dlsym.
// Each returns true, or false with what went wrong (no file name) in
// `error`; none throws.
#pragma once
#include <string>
#include <vector>

#include "src/trace/Image.h"
#include "vdb_bridge/PlotWriter.h"

namespace vdbdag::bridge::image_module {

// Writes a rendered frame to `path`, its format picked by the extension:
// .exr holds every channel as float, anything else 8-bit sRGB colour.
using WriteFrameFn = bool(const char* path, const trace::Image& image, std::string& error);
inline constexpr const char* kWriteFrame = "vdbdag_images_write_frame";

// Draws a log-log scatter plot (PlotWriter.h) and writes it as PNG to `path`.
using WritePlotFn = bool(const char* path, const std::vector<PlotSeries>& series, const PlotSpec& spec, std::string& error);
inline constexpr const char* kWritePlot = "vdbdag_images_write_plot";

inline constexpr const char* kModuleFile = "libvdbdag_images.so";

} // namespace vdbdag::bridge::image_module
