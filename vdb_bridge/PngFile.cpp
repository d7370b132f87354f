// See PngFile.h.
#include "vdb_bridge/PngFile.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <ostream>
#include <sstream>
#include <cstdlib>
#include <string>

#include "src/util/Error.h"

namespace vdbdag::bridge {
namespace {

constexpr size_t kIdatBytes = size_t(1) << 16;  // deflated bytes per IDAT chunk

void put32(std::vector<uint8_t>& out, uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(v >> s));
}

// A chunk: length, type, data, CRC-32 of type and data.
void chunk(std::vector<uint8_t>& out, const char type[4], std::span<const uint8_t> data) {
    put32(out, uint32_t(data.size()));
    const size_t typeAt = out.size();
    out.insert(out.end(), type, type + 4);
    out.insert(out.end(), data.begin(), data.end());
    put32(out, uint32_t(crc32(0, out.data() + typeAt, uInt(out.size() - typeAt))));
}

uint8_t paeth(int a, int b, int c) {
    const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
    return uint8_t(pa <= pb && pa <= pc ? a : pb <= pc ? b : c);
}

} // namespace

void writePng(std::ostream& out, int width, int height, std::span<const uint8_t> rgb) {
    if (width <= 0 || height <= 0 || uint64_t(width) * uint64_t(height) > (uint64_t(1) << 31) || rgb.size() != size_t(width) * size_t(height) * 3)
        throw Error("PNG: " + std::to_string(width) + "x" + std::to_string(height) + " pixels with " + std::to_string(rgb.size()) + " bytes");
    const size_t stride = size_t(width) * 3;
    std::vector<uint8_t> head{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::vector<uint8_t> header;
    put32(header, uint32_t(width));
    put32(header, uint32_t(height));
    header.insert(header.end(), {8, 2, 0, 0, 0});  // 8 bits, truecolour, deflate, adaptive filters, no interlace
    chunk(head, "IHDR", header);
    const uint8_t perceptual = 0;
    chunk(head, "sRGB", {&perceptual, 1});
    const auto emit = [&](const std::vector<uint8_t>& bytes) { out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size())); };
    emit(head);
    // Rows are filtered and deflated one at a time; each full buffer of
    // deflated bytes goes out as an IDAT chunk (the stream is written as it
    // is made, never held whole).
    z_stream z{};
    if (deflateInit(&z, 6) != Z_OK) throw Error("PNG: zlib could not start");
    std::vector<uint8_t> packed(kIdatBytes), pending;
    const auto drain = [&](int flush) {
        do {
            z.next_out = packed.data();
            z.avail_out = uInt(packed.size());
            const int rc = deflate(&z, flush);
            if (rc == Z_STREAM_ERROR) throw Error("PNG: zlib could not compress the pixels");
            const size_t made = packed.size() - z.avail_out;
            if (made) {
                pending.clear();
                chunk(pending, "IDAT", std::span<const uint8_t>(packed).first(made));
                emit(pending);
            }
        } while (z.avail_out == 0);
    };
    // Each row with its filter byte: of None, Sub, Up, Average and Paeth,
    // the one whose filtered bytes have the least sum of |signed value|.
    std::array<std::vector<uint8_t>, 5> trial;
    for (auto& t : trial) t.resize(stride + 1);
    const std::vector<uint8_t> zeros(stride, 0);
    try {
        for (int y = 0; y < height; ++y) {
            const uint8_t* row = rgb.data() + size_t(y) * stride;
            const uint8_t* up = y ? row - stride : zeros.data();
            uint64_t best = UINT64_MAX;
            size_t bestFilter = 0;
            for (size_t f = 0; f < 5; ++f) {
                uint64_t sum = 0;
                trial[f][0] = uint8_t(f);
                for (size_t i = 0; i < stride; ++i) {
                    const int a = i >= 3 ? row[i - 3] : 0, b = up[i], c = i >= 3 ? up[i - 3] : 0;
                    const uint8_t predicted = f == 0 ? 0 : f == 1 ? uint8_t(a) : f == 2 ? uint8_t(b) : f == 3 ? uint8_t((a + b) / 2) : paeth(a, b, c);
                    const uint8_t v = uint8_t(row[i] - predicted);
                    trial[f][i + 1] = v;
                    sum += v < 128 ? v : 256 - v;
                }
                if (sum < best) best = sum, bestFilter = f;
            }
            z.next_in = trial[bestFilter].data();
            z.avail_in = uInt(stride + 1);
            drain(Z_NO_FLUSH);
        }
        drain(Z_FINISH);
    } catch (...) {
        deflateEnd(&z);
        throw;
    }
    deflateEnd(&z);
    std::vector<uint8_t> tail;
    chunk(tail, "IEND", {});
    emit(tail);
}

std::vector<uint8_t> encodePng(int width, int height, std::span<const uint8_t> rgb) {
    std::ostringstream out;
    writePng(out, width, height, rgb);
    const std::string s = out.str();
    return {s.begin(), s.end()};
}

} // namespace vdbdag::bridge
