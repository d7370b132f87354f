// vdbdag's own PNG writer (vdb_bridge/PngFile.h) against OpenImageIO's
// reader (libpng): every pixel back as written, for sizes that exercise each
// row filter and several IDAT chunks, and the frame writer's sRGB codes
// against the closed form of IEC 61966-2-1.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "src/trace/Image.h"
#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "vdb_bridge/ImageWriter.h"
#include "vdb_bridge/PngFile.h"

namespace fs = std::filesystem;
using namespace vdbdag;

namespace {

std::vector<uint8_t> readWithOpenImageIO(const fs::path& path, int& width, int& height) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) return {};
    const OIIO::ImageSpec& spec = in->spec();
    width = spec.width;
    height = spec.height;
    EXPECT_EQ(spec.nchannels, 3);
    std::vector<uint8_t> pixels(size_t(width) * size_t(height) * 3);
    EXPECT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, pixels.data()));
    in->close();
    return pixels;
}

fs::path tempPng(const std::string& name) { return fs::temp_directory_path() / ("vdbdag_png_" + name + "_" + std::to_string(::getpid()) + ".png"); }

} // namespace

TEST(PngFile, EveryPixelReadsBackWithOpenImageIO) {
    std::mt19937 rng(11);
    struct Size {
        int w, h;
    };
    // 1x1; odd widths; a smooth gradient (Sub/Up/Paeth win) and noise (None
    // wins); 1100x700 noise spans several 64 KiB IDAT chunks.
    for (const Size s : {Size{1, 1}, Size{7, 3}, Size{64, 64}, Size{333, 17}, Size{1100, 700}}) {
        for (const bool noise : {false, true}) {
            std::vector<uint8_t> rgb(size_t(s.w) * size_t(s.h) * 3);
            for (int y = 0; y < s.h; ++y)
                for (int x = 0; x < s.w; ++x)
                    for (int c = 0; c < 3; ++c)
                        rgb[(size_t(y) * size_t(s.w) + size_t(x)) * 3 + size_t(c)] = noise ? uint8_t(rng()) : uint8_t(x * (c + 1) + y * 3);
            const fs::path path = tempPng("roundtrip");
            writeFileAtomically(path.string(), bridge::encodePng(s.w, s.h, rgb));
            int w = 0, h = 0;
            const std::vector<uint8_t> back = readWithOpenImageIO(path, w, h);
            EXPECT_EQ(w, s.w);
            EXPECT_EQ(h, s.h);
            EXPECT_TRUE(back == rgb) << s.w << "x" << s.h << (noise ? " noise" : " gradient");
            fs::remove(path);
        }
    }
    EXPECT_THROW(bridge::encodePng(0, 4, {}), Error);
    EXPECT_THROW(bridge::encodePng(2, 2, std::vector<uint8_t>(11)), Error);
}

TEST(PngFile, RenderedFramesAreSrgbCodes) {
    trace::Image image;
    image.resize(256, 2);
    for (int x = 0; x < 256; ++x) {
        const float linear = float(x) / 255.f;
        for (int c = 0; c < 3; ++c) image.rgb[size_t(x) * 3 + size_t(c)] = linear;
        image.rgb[(256 + size_t(x)) * 3 + 0] = std::nanf("");  // clamped to 0
        image.rgb[(256 + size_t(x)) * 3 + 1] = 2.f;             // clamped to 1
        image.rgb[(256 + size_t(x)) * 3 + 2] = -1.f;            // clamped to 0
    }
    const fs::path path = tempPng("frame");
    fs::remove(path);
    bridge::writeImage(path.string(), image);
    int w = 0, h = 0;
    const std::vector<uint8_t> back = readWithOpenImageIO(path, w, h);
    ASSERT_EQ(back.size(), size_t(256 * 2 * 3));
    for (int x = 0; x < 256; ++x) {
        const double l = double(x) / 255.0;
        const double srgb = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1 / 2.4) - 0.055;
        const int want = int(std::lround(srgb * 255.0));
        EXPECT_NEAR(int(back[size_t(x) * 3]), want, 0) << x;
        EXPECT_EQ(back[(256 + size_t(x)) * 3 + 0], 0);
        EXPECT_EQ(back[(256 + size_t(x)) * 3 + 1], 255);
        EXPECT_EQ(back[(256 + size_t(x)) * 3 + 2], 0);
    }
    fs::remove(path);
}
