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
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "src/volume/GridRecord.h"
#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge {

// Whether `path`'s extension names a dense format exportDense writes.
bool isDenseOutput(const std::string& path);

struct DenseExportOptions {
    bool showProgress = true;
    // A rescaled scan (DICOM Rescale Slope/Intercept, NIfTI scl_*) written
    // to a format without a rescale field (.nrrd, .nhdr, .mha, .mhd, .raw):
    // false (the default) writes the grid's values, in a type that holds
    // them exactly; true writes the stored integers, with the rescale as
    // NRRD key/value pairs rescale_slope / rescale_intercept or MetaImage
    // tags RescaleSlope / RescaleIntercept. NIfTI always gets the stored
    // integers and scl_slope / scl_inter.
    bool storedValues = false;
};

struct DenseExportReport {
    std::array<int64_t, 3> dims{0, 0, 0};
    SampleType type = SampleType::U8;
    std::string dataPath;  // the sample file (== path unless .nhdr / .mhd)
    // What a user should read: values written otherwise than stored, header
    // fields that could not go back (decode prints them).
    std::vector<std::string> notes;
};

// Throws vdbdag::Error naming `path` (or the grid) when the grid cannot be
// written as that format; nothing is left behind then.
DenseExportReport exportDense(const GridRecord& grid, const std::string& path, const DenseExportOptions& options = {});

// The grids of one 4-D scan (DenseImport's NAME_t0, NAME_t1, ... with
// metadata source_volume / source_volumes), as indices into `grids` in
// volume order; none unless every grid is one volume of the same series.
std::optional<std::vector<size_t>> volumeSeriesOf(const std::vector<GridRecord>& grids);
// Those volumes as one 4-D .nii / .nii.gz (dim[4] = their count) or .nrrd /
// .nhdr file (a last axis of kind "list"), the source's header fields as
// exportDense writes them; other formats are refused.
DenseExportReport exportDenseVolumes(const std::vector<const GridRecord*>& volumes, const std::string& path, const DenseExportOptions& options = {});

// Cube by cube, for a grid that does not fit in memory (decode from a DAG
// layer by layer, pipeline/LayerScatter.h): the voxels come in any order,
// a cube at a time, and are written at their offsets in the data file.
class DenseCubeSink {
public:
    virtual ~DenseCubeSink() = default;
    // A cube of 2^log2 voxels (index coordinates), then its bricks.
    virtual void beginCube(int64_t x, int64_t y, int64_t z, unsigned log2) = 0;
    // A brick inside the cube: its spatial mask and values (increasing
    // bit order; none for a mask grid, whose voxels are 1).
    virtual void brick(int64_t x, int64_t y, int64_t z, uint64_t mask, const uint8_t* values) = 0;
    // A solid node (anywhere): every voxel is `value`.
    virtual void solid(int64_t x, int64_t y, int64_t z, unsigned log2, const uint8_t* value) = 0;
    virtual void endCube() = 0;
};
// Whether `path` can be written this way for `header` (no voxels needed):
// a raw-encoded format (.nrrd, .nhdr, .mha, .mhd, .nii, .raw; not .nii.gz),
// a scalar int32/int64/float/double or mask grid, and the grid's recorded
// extent (source_dims, which DenseImport writes).
bool exportsByCubes(const GridRecord& header, const std::string& path);
// The same file as exportDense, atomically: `produce` hands every voxel to
// the sink; voxels it never gives are the background.
DenseExportReport exportDenseByCubes(const GridRecord& header, const std::string& path, const std::function<void(DenseCubeSink&)>& produce,
                                     const DenseExportOptions& options = {});

} // namespace vdbdag::bridge
