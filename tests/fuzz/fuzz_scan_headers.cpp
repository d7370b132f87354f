// libFuzzer target for the dense-scan readers: the first input byte picks
// the format (NRRD, MetaImage, NIfTI, gzip NIfTI, DICOM, raw), the rest is
// the file; for raw, the file's name (its layout, "NAME_XxYxZ_TYPE.raw")
// up to a NUL, then its samples. It is written to a private temporary file and read as vdbdag reads
// a scan: the header (NrrdHeader, MetaImageHeader, libnifti through
// NiftiHeader, GDCM through DicomSeries), then, when the header validates
// and describes at most 16 MiB of samples, every slice through
// openSliceReader. Any input must end in success or vdbdag::Error; anything
// else (a crash, a sanitizer report, another exception, a timeout, an
// out-of-memory) is a bug.
// Run: scripts/fuzz.sh [SECONDS] fuzz_scan_headers
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "src/util/Error.h"
#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/DicomSeries.h"
#include "vdb_bridge/MetaImageHeader.h"
#include "vdb_bridge/NiftiHeader.h"
#include "vdb_bridge/NrrdHeader.h"
#include "vdb_bridge/RawVolume.h"

namespace {

using namespace vdbdag;
using namespace vdbdag::bridge;

constexpr uint64_t kMaxSampleBytes = uint64_t(16) << 20;

const std::filesystem::path& folder() {
    static const std::filesystem::path dir = [] {
        std::filesystem::path d = std::filesystem::temp_directory_path() / ("vdbdag_fuzz_scan_" + std::to_string(getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

void readAll(const DenseVolume& v) {
    if (v.sampleCount() * sampleBytes(v.type) * v.components > kMaxSampleBytes) return;
    const std::unique_ptr<SliceReader> reader = openSliceReader(v);
    std::vector<uint8_t> slab;
    for (int64_t z = 0; z < v.dims[2]; z += 4) reader->readSlices(std::min<int64_t>(4, v.dims[2] - z), slab);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 1) return 0;
    static const char* const names[] = {"scan.nrrd", "scan.mha", "scan.nii", "scan.nii.gz", "scan.dcm", ""};
    const unsigned kind = data[0] % 6;
    size_t start = 1;
    std::string name = names[kind];
    if (kind == 5) {  // raw: the name is the header
        while (start < size && data[start] != 0 && name.size() < 200) {
            const char c = char(data[start++]);
            name += (c == '/' || c == '\0') ? '_' : c;
        }
        if (start < size && data[start] == 0) ++start;
        name = "r_" + name + ".raw";
    }
    const std::string path = (folder() / name).string();
    if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
        std::fwrite(data + start, 1, size - start, f);
        std::fclose(f);
    } else {
        return 0;
    }
    try {
        switch (kind) {
            case 0: readAll(readNrrdHeader(path)); break;
            case 1: readAll(readMetaImageHeader(path)); break;
            case 2:
            case 3: readAll(readNiftiHeader(path, 0)); break;
            case 4: {
                const DicomScan scan = scanDicom(path);
                if (!scan.series.empty()) readAll(describeDicomSeries(path, "1"));
                break;
            }
            case 5: readAll(describeRaw(path, RawLayout{})); break;
        }
    } catch (const Error&) {
    }
    std::filesystem::remove(path);
    return 0;
}
