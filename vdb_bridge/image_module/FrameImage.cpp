// libvdbdag_images.so: a rendered frame through OpenImageIO; see ImageModule.h.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <exception>
#include <filesystem>

#include <OpenImageIO/imageio.h>

#include "vdb_bridge/detail/Srgb.h"
#include "vdb_bridge/image_module/ImageModule.h"

namespace {

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

bool writeFrame(const std::string& path, const vdbdag::trace::Image& image, std::string& error) {
    const std::string ext = lowerExtension(path);
    const size_t pixels = size_t(image.width) * size_t(image.height);
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
        error = "OpenImageIO cannot write '" + ext + "' files: " + OIIO::geterror();
        return false;
    }
    bool ok = false;
    if (ext == ".exr") {
        OIIO::ImageSpec spec(image.width, image.height, 8, OIIO::TypeDesc::FLOAT);
        spec.channelnames = {"R", "G", "B", "A", "Z", "N.x", "N.y", "N.z"};
        spec.alpha_channel = 3;
        spec.z_channel = 4;
        spec.attribute("compression", "zip");
        std::vector<float> data(pixels * 8);
        for (size_t i = 0; i < pixels; ++i) {
            float* p = &data[8 * i];
            for (int c = 0; c < 3; ++c) p[c] = image.rgb[3 * i + c];
            p[3] = image.alpha[i];
            p[4] = image.depth[i];
            for (int c = 0; c < 3; ++c) p[5 + c] = image.normal[3 * i + c];
        }
        ok = out->open(path, spec) && out->write_image(OIIO::TypeDesc::FLOAT, data.data()) && out->close();
    } else {
        OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
        spec.attribute("oiio:ColorSpace", "sRGB");
        std::vector<uint8_t> data(pixels * 3);
        for (size_t i = 0; i < pixels * 3; ++i) data[i] = vdbdag::bridge::detail::srgbByte(image.rgb[i]);
        ok = out->open(path, spec) && out->write_image(OIIO::TypeDesc::UINT8, data.data()) && out->close();
    }
    if (!ok) {
        const std::string why = out->geterror();
        error = "cannot write the image: " + (why.empty() ? std::string("unknown error") : why);
    }
    return ok;
}

} // namespace

extern "C" __attribute__((visibility("default"))) bool vdbdag_images_write_frame(const char* path, const vdbdag::trace::Image& image,
                                                                                  std::string& error) {
    static_assert(std::is_same_v<decltype(vdbdag_images_write_frame), vdbdag::bridge::image_module::WriteFrameFn>);
    try {
        return writeFrame(path, image, error);
    } catch (const std::exception& e) {
        error = e.what();
        return false;
    }
}
