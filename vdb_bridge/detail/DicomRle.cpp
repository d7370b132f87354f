#include "vdb_bridge/detail/DicomRle.h"

#include <vector>

#include <fmt/core.h>
#include <gdcmDataSet.h>
#include <gdcmImageHelper.h>
#include <gdcmSequenceOfFragments.h>

#include "vdb_bridge/detail/DicomFileHeader.h"  // kPixelGroup

namespace vdbdag::bridge::detail {

namespace {

uint32_t le32(const uint8_t* p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

} // namespace

std::string rleFrameProblem(const uint8_t* frame, size_t size, unsigned segments, uint64_t frameBytes) {
    constexpr size_t kHeader = 64;  // a segment count and 15 offsets, little-endian
    if (segments == 0 || segments > 15) return fmt::format("{} RLE segments per frame, where DICOM allows 1 to 15", segments);
    if (frameBytes == 0) return "an RLE frame of no pixels";
    if (size < kHeader) return fmt::format("an RLE frame of {} bytes, shorter than its 64-byte header", size);
    const uint32_t count = le32(frame);
    if (count != segments)
        return fmt::format("an RLE header of {} segments where its pixels need {} (one per byte of a sample)", count, segments);
    if (frameBytes % segments) return fmt::format("{} bytes per frame, no multiple of its {} RLE segments", frameBytes, segments);
    const uint64_t perSegment = frameBytes / segments;
    uint64_t previous = 0;
    for (unsigned s = 0; s < segments; ++s) {
        const uint64_t begin = le32(frame + 4 + 4 * s);
        if (s == 0 ? begin != kHeader : begin <= previous || begin >= size)
            return fmt::format("RLE segment {} starts at byte {} of a {}-byte frame ({})", s + 1, begin, size,
                               s == 0 ? "the first must start at byte 64" : "not inside the frame after the segment before");
        previous = begin;
        // Decode as RLECodec::DecodeByStreams does: a control byte n, then
        // n + 1 literal bytes (n >= 0), one byte repeated 1 - n times
        // (-127 <= n <= -1), or nothing (n = -128), until the segment's
        // bytes are out; it may read on into the next segment, not past the
        // frame.
        uint64_t out = 0, at = begin;
        while (out < perSegment) {
            if (at >= size) return fmt::format("RLE segment {} runs past the end of its frame after {} of its {} bytes", s + 1, out, perSegment);
            const int n = int8_t(frame[at++]);
            const uint64_t read = n >= 0 ? uint64_t(n) + 1 : n == -128 ? 0 : 1;
            if (read > size - at) return fmt::format("RLE segment {} runs past the end of its frame after {} of its {} bytes", s + 1, out, perSegment);
            at += read;
            out += n >= 0 ? uint64_t(n) + 1 : n == -128 ? 0 : uint64_t(1 - n);
        }
        if (out != perSegment) return fmt::format("RLE segment {} decodes to {} bytes, not the {} of its share of the frame", s + 1, out, perSegment);
    }
    return "";
}

// RLE Lossless pixel data, frame by frame as GDCM's RLECodec reads them
// (detail/DicomRle.h), in the pixel format and frame count GDCM's image
// reader takes from the header: one fragment per frame of a multi-frame
// image, all fragments end to end for one frame.
std::string rleProblem(const gdcm::File& file) {
    const gdcm::PixelFormat pf = gdcm::ImageHelper::GetPixelFormatValue(file);
    const std::vector<unsigned int> dims = gdcm::ImageHelper::GetDimensionsValue(file);
    const unsigned bits = pf.GetBitsAllocated(), samples = pf.GetSamplesPerPixel();
    if ((bits != 8 && bits != 16 && bits != 32) || (samples != 1 && samples != 3))  // RLECodec asserts on others
        return fmt::format("RLE pixel data of {} bits allocated and {} samples per pixel (GDCM's RLE decoder takes 8, 16 or 32 bits, 1 or 3 samples)",
                           bits, samples);
    const uint64_t frames = dims.size() > 2 && dims[2] > 1 ? dims[2] : 1;
    const uint64_t frameBytes = uint64_t(dims.at(0)) * dims.at(1) * samples * (bits / 8);
    const gdcm::DataSet& ds = file.GetDataSet();
    const gdcm::Tag pixelData(kPixelGroup, 0x0010);
    const gdcm::SequenceOfFragments* sf = ds.FindDataElement(pixelData) ? ds.GetDataElement(pixelData).GetSequenceOfFragments() : nullptr;
    if (!sf || sf->GetNumberOfFragments() == 0) return "RLE pixel data without fragments";
    if (frames > 1 && sf->GetNumberOfFragments() != frames)
        return fmt::format("RLE pixel data of {} fragments for {} frames (one per frame)", sf->GetNumberOfFragments(), frames);
    std::vector<uint8_t> bytes;
    for (size_t i = 0; i < sf->GetNumberOfFragments(); ++i) {
        const gdcm::ByteValue* bv = sf->GetFragment(i).GetByteValue();
        if (bv && bv->GetLength()) bytes.insert(bytes.end(), bv->GetPointer(), bv->GetPointer() + bv->GetLength());
        if (frames == 1 && i + 1 < sf->GetNumberOfFragments()) continue;
        if (std::string bad = rleFrameProblem(bytes.data(), bytes.size(), samples * bits / 8, frameBytes); !bad.empty())
            return frames > 1 ? fmt::format("frame {}: {}", i + 1, bad) : bad;
        bytes.clear();
    }
    return "";
}

} // namespace vdbdag::bridge::detail
