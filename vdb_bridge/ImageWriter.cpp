// See ImageWriter.h: the frame is written by libvdbdag_images.so.
#include "vdb_bridge/ImageWriter.h"

#include <cstring>
#include <filesystem>
#include <fstream>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "vdb_bridge/detail/ImageModuleLoader.h"

namespace vdbdag::bridge {

namespace {

// OpenImageIO's PNG writer does not report a failed write (a full disk
// left a truncated PNG and exit 0, issue 38): a PNG is complete only when it
// ends with its IEND chunk (length 0, "IEND", CRC ae 42 60 82).
void checkPngIsComplete(const std::string& written, const std::string& path) {
    static const unsigned char kIend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
    std::ifstream in(written, std::ios::binary | std::ios::ate);
    const std::streamoff size = in ? std::streamoff(in.tellg()) : 0;
    unsigned char tail[12] = {};
    if (size >= 12) {
        in.seekg(size - 12);
        in.read(reinterpret_cast<char*>(tail), 12);
    }
    if (size < 12 || !in || std::memcmp(tail, kIend, 12) != 0)
        throw Error(path + ": the PNG could not be written completely (" + std::to_string(size) + " bytes, no IEND chunk: is the disk full?); nothing was written");
}

} // namespace

void writeImage(const std::string& path, const trace::Image& image) {
    const std::string ext = std::filesystem::path(path).extension().string();
    if (ext.empty()) throw Error(path + ": no file extension (use .png or .exr)");
    const detail::ImageModule& module = detail::imageModule(path);
    // The temporary keeps the extension, so OpenImageIO picks the format.
    writeViaTemporary(path, [&](const std::string& temp) {
        std::string error;
        if (!module.writeFrame(temp.c_str(), image, error)) throw Error(path + ": " + error);
        if (lowerExtension(path) == ".png") checkPngIsComplete(temp, path);
    }, ext);
}

} // namespace vdbdag::bridge
