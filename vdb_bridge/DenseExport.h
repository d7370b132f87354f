// A decoded grid back to a dense scan file, the inverse of DenseImport:
// .nrrd (attached) / .nhdr (+ NAME.raw), .mha (attached) / .mhd (+ NAME.raw),
// .nii / .nii.gz (NIfTI-1) and .raw (samples only).
//
// What comes back, from the grid's metadata (DenseImport records it):
// the full extent `source_dims` (else the active bounding box), the stored
// sample type `source_sample_type` (else the grid's own: int32, float,
// double; bool and mask as u8 0/1), the rescale `source_rescale_slope` /
// `_intercept` (undone exactly: a value it cannot have produced is an
// error), and the world transform, LPS when `space` says so (NIfTI is
// written in RAS, from LPS whether named or not, as ITK does; NRRD as "left-posterior-superior", MetaImage with
// AnatomicalOrientation RAI, ITK's name for LPS). Samples outside the active
// and stored-inactive voxels are the grid's background. Written slab by
// slab (4 z-slices of memory beside the grid), atomically.
#pragma once
#include <array>
#include <string>

#include "src/volume/GridRecord.h"
#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge {

// Whether `path`'s extension names a dense format exportDense writes.
bool isDenseOutput(const std::string& path);

struct DenseExportReport {
    std::array<int64_t, 3> dims{0, 0, 0};
    SampleType type = SampleType::U8;
    std::string dataPath;  // the sample file (== path unless .nhdr / .mhd)
};

// Throws vdbdag::Error naming `path` (or the grid) when the grid cannot be
// written as that format; nothing is left behind then.
DenseExportReport exportDense(const GridRecord& grid, const std::string& path, bool showProgress = true);

} // namespace vdbdag::bridge
