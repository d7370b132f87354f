// The shared description of a dense scan (what the raw, NRRD and MetaImage
// readers produce) and the sample stream that reads it slice by slice.
// Sample (i, j, k), i fastest in the file, sits at index coordinate (i, j, k);
// world = origin + i * axis[0] + j * axis[1] + k * axis[2], so each axis
// vector carries its spacing (NRRD "space directions", MetaImage
// ElementSpacing times the TransformMatrix row). No OpenVDB types here.
#pragma once
#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace vdbdag::bridge {

enum class SampleType : uint8_t { U8, I8, U16, I16, U32, I32, F32, F64 };
const char* sampleTypeName(SampleType type);  // "u8", ..., "f64"
unsigned sampleBytes(SampleType type);
bool isIntegerSample(SampleType type);
// "u8|i8|u16|i16|u32|i32|f32|f64"; throws vdbdag::Error naming `what` otherwise.
SampleType parseSampleType(const std::string& name, const std::string& what);

enum class DataEncoding : uint8_t { Raw, Zlib };  // Zlib: gzip or zlib stream (detected)

struct DenseVolume {
    std::string headerPath;  // the file the user named (for messages)
    std::string dataPath;    // where the samples are (may equal headerPath)
    std::string dataNameInHeader;  // the data file as the header names it (empty when attached)
    std::array<int64_t, 3> dims{0, 0, 0};
    SampleType type = SampleType::U8;
    bool bigEndian = false;
    DataEncoding encoding = DataEncoding::Raw;
    // Bytes to skip in the data file before the samples (for Zlib: before
    // the compressed stream); kSkipToEnd: the samples are the file's last bytes.
    int64_t dataOffset = 0;
    static constexpr int64_t kSkipToEnd = -1;
    // Bytes to skip after decompression (NRRD "byte skip" with gzip).
    int64_t decodedSkip = 0;
    // Lines to skip at the start of the data (NRRD "line skip", raw only).
    int64_t lineSkip = 0;
    std::array<double, 3> origin{0, 0, 0};
    std::array<std::array<double, 3>, 3> axes{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};

    uint64_t sampleCount() const { return uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]); }
    uint64_t sliceSamples() const { return uint64_t(dims[0]) * uint64_t(dims[1]); }
    // Checks dims (positive, at most 2^31 - 1 each, at most 2^40 samples),
    // finite origin and an invertible, finite axis matrix. Throws vdbdag::Error.
    void validate() const;
};

// Reads whole z-slices in file order, converted to host byte order (raw
// sample bytes, sampleBytes(type) each). Checks that the data file exists and
// is long enough when opened; a short or corrupt stream is reported naming
// the data file. Never reads more than it needs.
class DenseSampleStream {
public:
    explicit DenseSampleStream(const DenseVolume& volume);
    ~DenseSampleStream();
    DenseSampleStream(const DenseSampleStream&) = delete;
    DenseSampleStream& operator=(const DenseSampleStream&) = delete;

    // Reads the next `slices` slices into `out` (resized to
    // slices * sliceSamples * sampleBytes). Throws vdbdag::Error.
    void readSlices(int64_t slices, std::vector<uint8_t>& out);

private:
    void readBytes(uint8_t* out, size_t n);
    std::string where() const;  // "HEADER: data file DATA", or the file itself
    void skipDecoded(uint64_t n);
    DenseVolume volume_;
    std::FILE* file_ = nullptr;
    struct Inflater;
    std::unique_ptr<Inflater> inflater_;
    int64_t slicesRead_ = 0;
};

// Which dense format a path names, by extension: ".nrrd", ".nhdr", ".mhd",
// ".mha", ".raw" (case-insensitive); None for anything else (e.g. ".vdb").
enum class DenseFormat { None, Raw, Nrrd, MetaImage };
DenseFormat denseFormatOf(const std::string& path);

} // namespace vdbdag::bridge
