// See ImageWriter.h: a PNG is written by vdbdag (PngFile.h), anything else
// by libvdbdag_images.so (OpenImageIO).
#include "vdb_bridge/ImageWriter.h"

#include <filesystem>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "vdb_bridge/PngFile.h"
#include "vdb_bridge/detail/ImageModuleLoader.h"
#include "vdb_bridge/detail/Srgb.h"

namespace vdbdag::bridge {

void writeImage(const std::string& path, const trace::Image& image) {
    const std::string ext = std::filesystem::path(path).extension().string();
    if (ext.empty()) throw Error(path + ": no file extension (use .png or .exr)");
    if (lowerExtension(path) == ".png") {
        std::vector<uint8_t> rgb(image.rgb.size());
        for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = detail::srgbByte(image.rgb[i]);
        writeStreamAtomically(path, [&](std::ostream& out) { writePng(out, image.width, image.height, rgb); });
        return;
    }
    const detail::ImageModule& module = detail::imageModule(path);
    // The temporary keeps the extension, so OpenImageIO picks the format.
    writeViaTemporary(path, [&](const std::string& temp) {
        std::string error;
        if (!module.writeFrame(temp.c_str(), image, error)) throw Error(path + ": " + error);
    }, ext);
}

} // namespace vdbdag::bridge
