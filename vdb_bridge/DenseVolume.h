// The shared description of a dense scan (what the raw, NRRD, MetaImage,
// NIfTI and DICOM readers produce) and the readers that give its samples
// slice by slice.
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
#include <utility>
#include <variant>
#include <vector>

namespace vdbdag::bridge {

namespace detail {
class InflateCheckpoints;
}

enum class SampleType : uint8_t { U8, I8, U16, I16, U32, I32, F32, F64 };
const char* sampleTypeName(SampleType type);  // "u8", ..., "f64"
unsigned sampleBytes(SampleType type);
bool isIntegerSample(SampleType type);
// The values an integer sample type holds, [min, max], narrowed to its low
// `bits` when given (DICOM Bits Stored); NaN for float types.
std::pair<double, double> sampleRange(SampleType type, unsigned bits = 0);
// "u8|i8|u16|i16|u32|i32|f32|f64"; throws vdbdag::Error naming `what` otherwise.
SampleType parseSampleType(const std::string& name, const std::string& what);

enum class DataEncoding : uint8_t { Raw, Zlib };  // Zlib: gzip or zlib stream (detected)

// Which dense format a path names: by extension ".nrrd", ".nhdr", ".mhd",
// ".mha", ".raw", ".nii", ".nii.gz", ".hdr" (case-insensitive); a folder, a
// ".dcm" file or a DICOMDIR is DICOM; None for anything else (e.g. ".vdb").
enum class DenseFormat { None, Raw, Nrrd, MetaImage, Nifti, Dicom };
DenseFormat denseFormatOf(const std::string& path);
const char* denseFormatName(DenseFormat format);  // "raw", "nrrd", "metaimage", "nifti", "dicom"
// A scan's name: its file name without the extension (".nii.gz" as one).
std::string scanNameOf(const std::string& path);

// One slice of a DICOM series: a file, and the frame within it (0 for
// single-frame files).
struct DicomSlice {
    std::string file;
    uint32_t frame = 0;
};

// One field of the source file's header, kept in the grid's metadata under
// `key` (docs/SCAN_METADATA.md lists the keys) so that a decode to the same
// format writes it back: NIfTI's "nifti_*" fields, for instance.
struct HeaderField {
    using Value = std::variant<int64_t, double, std::string>;
    std::string key;
    Value value;
};

struct DenseVolume {
    DenseFormat format = DenseFormat::Raw;
    std::string headerPath;  // the file the user named (for messages)
    std::string gridName;    // the grid's name when not the file's (a NIfTI volume: NAME_tN)
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
    // The patient space of origin and axes: "LPS" (DICOM, NRRD
    // "left-posterior-superior"), "RAS" (NIfTI), "LAS", or empty when the
    // header names none. describeDense turns RAS and LAS into LPS, so every
    // grid of a scan with a patient space is in LPS (as DICOM, ITK, Slicer).
    std::string space;
    // value = stored sample * slope + intercept (DICOM Rescale Slope and
    // Intercept, NIfTI scl_slope / scl_inter); identity by default.
    double rescaleSlope = 1, rescaleIntercept = 0;
    // Vector and colour scans: components per sample (1 or 3), interleaved
    // in the file (NRRD's leading axis, MetaImage ElementNumberOfChannels,
    // NIfTI RGB24) or, when componentStride > 0, in planes that many bytes
    // apart (NIfTI's 5th dimension). Readers always give them interleaved.
    unsigned components = 1;
    uint64_t componentStride = 0;
    bool colour = false;  // RGB: a colour grid named "Cd"
    // Interleaved samples with more components in the file than are read
    // (NIfTI RGBA32: 4, read as RGB "Cd" and, separately, as "alpha"): the
    // reader gives components [firstComponent, firstComponent + components)
    // of each storedComponents. 0: as many as are read.
    unsigned storedComponents = 0, firstComponent = 0;
    unsigned componentsInFile() const { return storedComponents > components ? storedComponents : components; }
    // DICOM: the slices in order along the slice normal (dims[2] of them).
    std::vector<DicomSlice> slices;
    // Slices with no data (a DICOM series missing some): their samples are
    // not read and become inactive voxels. Sorted.
    std::vector<int64_t> missingSlices;
    // What a user should know about how the file was read (e.g. missing
    // slices kept empty); `encode` prints them as warnings.
    std::vector<std::string> notes;
    // The source header's fields beyond what the members above hold.
    std::vector<HeaderField> headerFields;
    // Bits of each integer sample that hold data (DICOM Bits Stored: 12 for
    // most CT in 16-bit samples); 0 when the header does not say (then the
    // sample type's width). PSNR's peak and a decode's output type use it.
    unsigned bitsStored = 0;
    // One volume of a 4-D file (a NIfTI time series): its index, 0-based,
    // and how many the file holds; -1 and 1 for a 3-D scan. A decode to
    // NIfTI writes the grids of one series back as one 4-D file.
    int64_t volumeIndex = -1, volumeCount = 1;
    // Where readers of a compressed data file may resume decoding it
    // (detail/InflateCheckpoints.h): shared by the volumes of one 4-D file
    // while importDense reads them in turn; null otherwise.
    std::shared_ptr<detail::InflateCheckpoints> resume;

    uint64_t sampleCount() const { return uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]); }
    uint64_t sliceSamples() const { return uint64_t(dims[0]) * uint64_t(dims[1]); }
    // Checks dims (positive, at most 2^31 - 1 each, at most 2^40 samples),
    // finite origin and an invertible, finite axis matrix. Throws vdbdag::Error.
    void validate() const;
};

// Gives a scan's stored samples (before any rescale) whole z-slices at a
// time, in order, in host byte order (sampleBytes(type) each).
class SliceReader {
public:
    virtual ~SliceReader() = default;
    // Reads the next `slices` slices into `out` (resized to
    // slices * sliceSamples * sampleBytes). Throws vdbdag::Error naming the file.
    virtual void readSlices(int64_t slices, std::vector<uint8_t>& out) = 0;
};

// The reader for `volume`'s format (DICOM: DicomSeries.h; the others: a
// DenseSampleStream). Checks what it can before the first slice (the data
// file's size against the header).
std::unique_ptr<SliceReader> openSliceReader(const DenseVolume& volume);

// Reads one data file (raw, NRRD, MetaImage, NIfTI): checks that it exists
// and is long enough when opened; a short or corrupt stream is reported
// naming the data file. Never reads more than it needs.
class DenseSampleStream : public SliceReader {
public:
    explicit DenseSampleStream(const DenseVolume& volume);
    ~DenseSampleStream() override;
    DenseSampleStream(const DenseSampleStream&) = delete;
    DenseSampleStream& operator=(const DenseSampleStream&) = delete;

    void readSlices(int64_t slices, std::vector<uint8_t>& out) override;

private:
    void readBytes(uint8_t* out, size_t n);
    std::string where() const;  // "HEADER: data file DATA", or the file itself
    void positionAt(uint64_t fileSize, uint64_t need);  // the constructor's checks and seek, once the file is open
    void skipDecoded(uint64_t n);
    void keepPosition();  // volume_.resume: where the decoding has come to
    std::string streamName() const;  // the compressed stream, for volume_.resume
    DenseVolume volume_;
    std::FILE* file_ = nullptr;
    struct Inflater;
    std::unique_ptr<Inflater> inflater_;
    int64_t slicesRead_ = 0;
};

} // namespace vdbdag::bridge
