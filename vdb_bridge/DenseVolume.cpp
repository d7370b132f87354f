// See DenseVolume.h. The stream reads raw bytes with fread or inflates a
// gzip/zlib stream with zlib (inflateInit2 with window bits 15 + 32 detects
// either header), in fixed 1 MiB input chunks, so memory stays at one slab.
#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/DicomSeries.h"
#include "vdb_bridge/detail/InflateCheckpoints.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include <zlib.h>

#include "src/util/Error.h"

namespace vdbdag::bridge {

const char* sampleTypeName(SampleType type) {
    switch (type) {
        case SampleType::U8: return "u8";
        case SampleType::I8: return "i8";
        case SampleType::U16: return "u16";
        case SampleType::I16: return "i16";
        case SampleType::U32: return "u32";
        case SampleType::I32: return "i32";
        case SampleType::F32: return "f32";
        case SampleType::F64: return "f64";
    }
    return "?";
}

unsigned sampleBytes(SampleType type) {
    switch (type) {
        case SampleType::U8: case SampleType::I8: return 1;
        case SampleType::U16: case SampleType::I16: return 2;
        case SampleType::U32: case SampleType::I32: case SampleType::F32: return 4;
        case SampleType::F64: return 8;
    }
    return 1;
}

bool isIntegerSample(SampleType type) { return type != SampleType::F32 && type != SampleType::F64; }

std::pair<double, double> sampleRange(SampleType type, unsigned bits) {
    if (!isIntegerSample(type)) return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    const bool isSigned = type == SampleType::I8 || type == SampleType::I16 || type == SampleType::I32;
    const int b = int(bits ? bits : 8 * sampleBytes(type));
    if (isSigned) return {-std::ldexp(1.0, b - 1), std::ldexp(1.0, b - 1) - 1};
    return {0.0, std::ldexp(1.0, b) - 1};
}

SampleType parseSampleType(const std::string& name, const std::string& what) {
    for (SampleType t : {SampleType::U8, SampleType::I8, SampleType::U16, SampleType::I16, SampleType::U32, SampleType::I32, SampleType::F32,
                         SampleType::F64})
        if (name == sampleTypeName(t)) return t;
    throw Error(what + ": unsupported sample type '" + name + "' (use u8, i8, u16, i16, u32, i32, f32 or f64)");
}

void DenseVolume::validate() const {
    for (int a = 0; a < 3; ++a)
        if (dims[a] < 1 || dims[a] > 0x7FFFFFFF)
            throw Error(headerPath + ": size " + std::to_string(dims[a]) + " along axis " + std::to_string(a) + " is out of range (1 to 2^31-1)");
    if (double(dims[0]) * double(dims[1]) * double(dims[2]) > double(uint64_t(1) << 40))
        throw Error(headerPath + ": " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" + std::to_string(dims[2]) +
                    " samples is an absurd size (more than 2^40)");
    // Index coordinates must fit OpenVDB's signed 32-bit coordinates.
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(origin[a])) throw Error(headerPath + ": the origin is not finite");
    for (const auto& axis : axes)
        for (double v : axis)
            if (!std::isfinite(v)) throw Error(headerPath + ": an axis direction or spacing is not finite");
    const auto& m = axes;
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    double scale = 0;
    for (const auto& axis : axes) scale = std::max(scale, std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]));
    if (!(std::abs(det) > 1e-12 * scale * scale * scale) || scale == 0)
        throw Error(headerPath + ": the axis directions/spacings are degenerate (zero spacing or parallel axes)");
}

DenseFormat denseFormatOf(const std::string& path) {
    auto lower = [](std::string t) {
        std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        return t;
    };
    const std::filesystem::path p(path);
    const std::string ext = lower(p.extension().string());
    const std::string name = lower(p.filename().string());
    if (ext == ".raw") return DenseFormat::Raw;
    if (ext == ".nrrd" || ext == ".nhdr") return DenseFormat::Nrrd;
    if (ext == ".mhd" || ext == ".mha") return DenseFormat::MetaImage;
    if (ext == ".nii" || ext == ".hdr" || (name.size() > 7 && name.ends_with(".nii.gz"))) return DenseFormat::Nifti;
    if (ext == ".dcm" || name == "dicomdir") return DenseFormat::Dicom;
    std::error_code ec;
    if (std::filesystem::is_directory(p, ec)) return DenseFormat::Dicom;
    // A DICOM file by its content (slices often have no extension): the
    // "DICM" prefix after the 128-byte preamble (PS3.10 7.1).
    if (ext != ".vdb" && ext != ".ssvdag" && std::filesystem::is_regular_file(p, ec)) {
        if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
            char head[132] = {};
            const bool dicm = std::fread(head, 1, sizeof head, f) == sizeof head && std::memcmp(head + 128, "DICM", 4) == 0;
            std::fclose(f);
            if (dicm) return DenseFormat::Dicom;
        }
    }
    return DenseFormat::None;
}

std::string scanNameOf(const std::string& path) {
    std::string name = std::filesystem::path(path).filename().string();
    std::string lower = name;
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (lower.size() > 7 && lower.ends_with(".nii.gz")) return name.substr(0, name.size() - 7);
    return std::filesystem::path(name).stem().string();
}

const char* denseFormatName(DenseFormat format) {
    switch (format) {
        case DenseFormat::None: return "none";
        case DenseFormat::Raw: return "raw";
        case DenseFormat::Nrrd: return "nrrd";
        case DenseFormat::MetaImage: return "metaimage";
        case DenseFormat::Nifti: return "nifti";
        case DenseFormat::Dicom: return "dicom";
    }
    return "none";
}

namespace {

// Component planes (NIfTI's 5th dimension), one stream each, interleaved
// slab by slab.
class PlanarReader : public SliceReader {
public:
    explicit PlanarReader(const DenseVolume& v) : sampleBytes_(sampleBytes(v.type)), components_(v.components) {
        for (unsigned c = 0; c < v.components; ++c) {
            DenseVolume plane = v;
            plane.components = 1;
            plane.componentStride = 0;
            const int64_t shift = int64_t(c * v.componentStride);
            if (v.encoding == DataEncoding::Zlib) plane.decodedSkip += shift;
            else plane.dataOffset += shift;
            planes_.push_back(std::make_unique<DenseSampleStream>(plane));
        }
    }
    void readSlices(int64_t slices, std::vector<uint8_t>& out) override {
        std::vector<uint8_t> plane;
        for (unsigned c = 0; c < components_; ++c) {
            planes_[c]->readSlices(slices, plane);
            const size_t n = plane.size() / sampleBytes_;
            if (c == 0) out.resize(plane.size() * components_);
            for (size_t i = 0; i < n; ++i)
                std::memcpy(out.data() + (i * components_ + c) * sampleBytes_, plane.data() + i * sampleBytes_, sampleBytes_);
        }
    }

private:
    unsigned sampleBytes_, components_;
    std::vector<std::unique_ptr<DenseSampleStream>> planes_;
};

} // namespace

std::unique_ptr<SliceReader> openSliceReader(const DenseVolume& volume) {
    if (volume.format == DenseFormat::Dicom) return openDicomSlices(volume);
    if (volume.components > 1 && volume.componentStride > 0) return std::make_unique<PlanarReader>(volume);
    return std::make_unique<DenseSampleStream>(volume);
}

struct DenseSampleStream::Inflater {
    z_stream z{};
    std::vector<uint8_t> input = std::vector<uint8_t>(1u << 20);
    bool ended = false;
    bool failed = false;  // a read threw: its state is no position to resume from
    ~Inflater() { inflateEnd(&z); }
};

DenseSampleStream::DenseSampleStream(const DenseVolume& volume) : volume_(volume) {
    volume_.validate();
    const std::string& data = volume_.dataPath;
    std::error_code ec;
    if (!std::filesystem::exists(data, ec))
        throw Error(volume_.headerPath + ": data file " + data + " does not exist");
    if (!std::filesystem::is_regular_file(data, ec))
        throw Error(volume_.headerPath + ": data file " + data + " is not a regular file (a directory, device or FIFO is never read)");
    const uint64_t fileSize = std::filesystem::file_size(data, ec);
    if (ec) throw Error(where() + ": cannot read the file size (" + ec.message() + ")");
    const uint64_t need = volume_.sampleCount() * sampleBytes(volume_.type) * volume_.componentsInFile();
    file_ = std::fopen(data.c_str(), "rb");
    if (!file_) throw Error(where() + ": cannot open (" + std::strerror(errno) + ")");
    // A constructor that throws runs no destructor: the file is closed here
    // (a descriptor leaked with each refused header; fuzz_scan_headers ran
    // out of its 20,000 after 1.6 million inputs).
    try {
        positionAt(fileSize, need);
    } catch (...) {
        std::fclose(file_);
        file_ = nullptr;
        throw;
    }
}

void DenseSampleStream::positionAt(uint64_t fileSize, uint64_t need) {
    int64_t offset = volume_.dataOffset;
    if (volume_.encoding == DataEncoding::Raw) {
        if (offset == DenseVolume::kSkipToEnd) {
            if (fileSize < need)
                throw Error(where() + ": holds " + std::to_string(fileSize) + " bytes, fewer than the " + std::to_string(need) + " the header describes");
            offset = int64_t(fileSize - need);
        }
        if (offset < 0 || uint64_t(offset) > fileSize) throw Error(where() + ": data offset " + std::to_string(offset) + " is beyond the end of the file");
        if (std::fseek(file_, long(offset), SEEK_SET) != 0) throw Error(where() + ": cannot seek to byte " + std::to_string(offset));
        for (int64_t l = 0; l < volume_.lineSkip; ++l) {
            int c;
            while ((c = std::fgetc(file_)) != EOF && c != '\n') {}
            if (c == EOF) throw Error(where() + ": ends before the " + std::to_string(volume_.lineSkip) + " lines to skip");
        }
        const uint64_t at = uint64_t(std::ftell(file_)) + uint64_t(volume_.decodedSkip);
        if (fileSize < at || fileSize - at < need)
            throw Error(where() + ": too short: " + std::to_string(fileSize < at ? 0 : fileSize - at) + " bytes of samples, the header describes " +
                        std::to_string(volume_.dims[0]) + "x" + std::to_string(volume_.dims[1]) + "x" + std::to_string(volume_.dims[2]) + " " +
                        sampleTypeName(volume_.type) + (volume_.componentsInFile() > 1 ? " x " + std::to_string(volume_.componentsInFile()) + " components" : "") +
                        " = " + std::to_string(need) + " bytes");
        if (volume_.decodedSkip && std::fseek(file_, long(volume_.decodedSkip), SEEK_CUR) != 0)
            throw Error(where() + ": cannot skip " + std::to_string(volume_.decodedSkip) + " bytes");
    } else {
        if (offset < 0 || uint64_t(offset) > fileSize) throw Error(where() + ": compressed data offset is beyond the end of the file");
        if (std::fseek(file_, long(offset), SEEK_SET) != 0) throw Error(where() + ": cannot seek to byte " + std::to_string(offset));
        // zlib's deflate expands at most about 1032:1: a header that claims
        // more samples than that is refused before anything is allocated.
        if (need / 1032 > fileSize - uint64_t(offset))
            throw Error(where() + ": " + std::to_string(fileSize - uint64_t(offset)) + " compressed bytes cannot hold the " + std::to_string(need) +
                        " bytes of samples the header describes");
        inflater_ = std::make_unique<Inflater>();
        if (inflateInit2(&inflater_->z, 15 + 32) != Z_OK) throw Error(where() + ": cannot start zlib");
        uint64_t skip = uint64_t(volume_.decodedSkip);
        if (volume_.resume)
            if (const auto at = volume_.resume->restore(streamName(), skip, inflater_->z)) {  // where an earlier reader of the file left off
                if (std::fseek(file_, long(at->filePosition), SEEK_SET) != 0) throw Error(where() + ": cannot seek to byte " + std::to_string(at->filePosition));
                skip -= at->decoded;
            }
        skipDecoded(skip);
        keepPosition();
    }
}

std::string DenseSampleStream::where() const {
    if (volume_.dataPath == volume_.headerPath) return volume_.dataPath;
    return volume_.headerPath + ": data file " + volume_.dataPath;
}

DenseSampleStream::~DenseSampleStream() {
    try {
        keepPosition();  // where the next volume of a 4-D file starts
    } catch (...) {
    }
    if (file_) std::fclose(file_);
}

void DenseSampleStream::keepPosition() {
    if (!volume_.resume || !inflater_ || inflater_->ended || inflater_->failed || !file_) return;
    const long at = std::ftell(file_);
    if (at < 0 || uint64_t(at) < inflater_->z.avail_in) return;
    volume_.resume->save(streamName(), inflater_->z, uint64_t(at) - inflater_->z.avail_in);
}

std::string DenseSampleStream::streamName() const { return volume_.dataPath + " at byte " + std::to_string(volume_.dataOffset); }

void DenseSampleStream::readBytes(uint8_t* out, size_t n) {
    if (!inflater_) {
        if (std::fread(out, 1, n, file_) != n) throw Error(where() + ": short read (the file ended or could not be read)");
        return;
    }
    Inflater& inf = *inflater_;
    inf.failed = true;  // until every byte is read: a reader that threw keeps no position
    inf.z.next_out = out;
    inf.z.avail_out = 0;
    size_t left = n;
    while (left) {
        const size_t chunk = std::min<size_t>(left, 1u << 30);
        inf.z.next_out = out + (n - left);
        inf.z.avail_out = unsigned(chunk);
        while (inf.z.avail_out) {
            if (inf.ended)
                throw Error(where() + ": the compressed data ends early (" + std::to_string(volume_.sampleCount()) + " samples expected)");
            if (inf.z.avail_in == 0) {
                const size_t got = std::fread(inf.input.data(), 1, inf.input.size(), file_);
                if (got == 0) throw Error(where() + ": the compressed data is truncated");
                inf.z.next_in = inf.input.data();
                inf.z.avail_in = unsigned(got);
            }
            const int rc = inflate(&inf.z, Z_NO_FLUSH);
            if (rc == Z_STREAM_END) {
                inf.ended = true;
            } else if (rc != Z_OK && rc != Z_BUF_ERROR) {
                throw Error(where() + ": the compressed data is corrupt (zlib: " + (inf.z.msg ? inf.z.msg : "error") + ")");
            }
        }
        left -= chunk;
    }
    inf.failed = false;
}

void DenseSampleStream::skipDecoded(uint64_t n) {
    std::vector<uint8_t> scratch(std::min<uint64_t>(n, 1u << 20));
    while (n) {
        const size_t k = size_t(std::min<uint64_t>(n, scratch.size()));
        readBytes(scratch.data(), k);
        n -= k;
    }
}

void DenseSampleStream::readSlices(int64_t slices, std::vector<uint8_t>& out) {
    if (slices < 0 || slicesRead_ + slices > volume_.dims[2]) throw Error(volume_.headerPath + ": internal error: reading past the last slice");
    const unsigned sb = sampleBytes(volume_.type);
    const unsigned stored = volume_.componentsInFile(), kept = volume_.components;
    const size_t samples = size_t(uint64_t(slices) * volume_.sliceSamples());
    const size_t n = samples * sb * kept;
    out.resize(samples * sb * stored);
    readBytes(out.data(), out.size());
    slicesRead_ += slices;
    if (stored != kept) {  // keep components [first, first + kept) of each sample, in place
        const size_t first = size_t(volume_.firstComponent) * sb, keptBytes = size_t(kept) * sb, storedBytes = size_t(stored) * sb;
        for (size_t i = 0; i < samples; ++i) std::memmove(out.data() + i * keptBytes, out.data() + i * storedBytes + first, keptBytes);
        out.resize(n);
    }
    // Samples to host (little-endian) order.
    if (volume_.bigEndian && sb > 1) {
        uint8_t* p = out.data();
        for (size_t i = 0; i < n; i += sb) std::reverse(p + i, p + i + sb);
    }
}

} // namespace vdbdag::bridge
