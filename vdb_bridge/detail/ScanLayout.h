// How a grid becomes the samples of a scan file (DenseExport): the output
// format named by the path, the extent, the sample type (the source's, or
// the grid's values when the format has no rescale field), the transform
// and the source header's fields. No samples, no files.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "src/volume/GridRecord.h"
#include "vdb_bridge/DenseExport.h"
#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/NiftiFields.h"

namespace vdbdag::bridge::detail {

enum class OutFormat { Nrrd, Nhdr, Mha, Mhd, Nii, NiiGz, Raw };
// By extension (case-insensitive); none for anything else.
std::optional<OutFormat> outFormatOf(const std::string& path);

// Where the samples go and how the file describes them.
struct ScanLayout {
    std::array<int64_t, 3> dims{0, 0, 0};
    std::array<int64_t, 3> lo{0, 0, 0};  // index coordinate of sample (0, 0, 0)
    SampleType type = SampleType::I32;
    // The samples are stored integers: value = sample * slope + intercept.
    bool rescaled = false;
    double slope = 1, intercept = 0;
    std::array<double, 3> origin{0, 0, 0};  // world position of sample (0, 0, 0)
    std::array<std::array<double, 3>, 3> axes{};
    std::string space;  // "LPS" or empty
    // The unit of world coordinates when the source said ("mm", "m", "um":
    // NIfTI xyzt_units, NRRD space units), else empty (readers take mm).
    std::string spaceUnit;
    unsigned components = 1;  // 3 for vector and colour grids
    int64_t volumes = 1;      // the volumes of a 4-D file (NIfTI dim[4], NRRD's last axis), one after the other
    bool colour = false;      // RGB (NIfTI RGB24, NRRD "RGB-color")
    // The source's NIfTI header fields (NiftiFields.h), for a NIfTI output.
    HeaderFieldMap nifti;
    // The grid's transform is the one `nifti` gives (niftiGridTransformOf).
    bool niftiGeometry = false;
    // NRRD key/value pairs ("key:=value") and MetaImage tags ("Key = value")
    // written after the format's own fields; NRRD fields ("name: value")
    // the writer does not derive itself (the source's, nrrd_field_*).
    std::vector<std::pair<std::string, std::string>> keyValues, nrrdFields;
    uint64_t sliceSamples() const { return uint64_t(dims[0]) * uint64_t(dims[1]); }
};

// The layout of `grid` written to `path` as `format`, from its metadata
// (DenseImport's source_* keys, docs/SCAN_METADATA.md) or, without them,
// from its value type and bounding box. `notes` gets what the user should
// know (values written otherwise than stored). Throws vdbdag::Error naming
// `path` and the grid when it cannot be written so.
ScanLayout layoutOf(const GridRecord& grid, const std::string& path, OutFormat format, const DenseExportOptions& options, std::vector<std::string>& notes);

} // namespace vdbdag::bridge::detail
