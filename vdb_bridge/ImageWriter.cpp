// See ImageWriter.h: the frame is written by libvdbdag_images.so.
#include "vdb_bridge/ImageWriter.h"

#include <filesystem>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "vdb_bridge/detail/ImageModuleLoader.h"

namespace vdbdag::bridge {

void writeImage(const std::string& path, const trace::Image& image) {
    const std::string ext = std::filesystem::path(path).extension().string();
    if (ext.empty()) throw Error(path + ": no file extension (use .png or .exr)");
    const detail::ImageModule& module = detail::imageModule(path);
    // The temporary keeps the extension, so OpenImageIO picks the format.
    writeViaTemporary(path, [&](const std::string& temp) {
        std::string error;
        if (!module.writeFrame(temp.c_str(), image, error)) throw Error(path + ": " + error);
    }, ext);
}

} // namespace vdbdag::bridge
