// Dense scans (raw, NRRD, MetaImage) -> vdbdag's Volume: one grid whose
// voxels are the samples, streamed in z-slabs of 4 slices straight into 4^3
// bricks, so memory holds the grid's values once plus one slab.
//
// Value type (DESIGN.md invariant 4, samples come back exactly): u8, i8,
// u16, i16 and i32 samples become an Int32 grid; u32 an Int64 grid (its
// values need 32 bits unsigned); f32 a Float grid, f64 a Double grid (bit
// for bit, NaN payloads included). Integer samples are never stored as
// floats. Grid class "unknown", background 0; the transform is the affine map
// of the header's spacing, directions and origin; metadata records the
// source file and sample type.
//
// Thresholds (--background-below V / --background-above V): samples < V (or
// > V) become inactive background, so the DAG's sparsity applies. The
// background value is --background-value, or else the mean of the removed
// samples (rounded for integer grids), the least-squares choice; a first pass over the data finds it. The
// report states what that costs against the input: samples changed, max,
// mean and RMS absolute change, PSNR with peak = the input's value range.
#pragma once
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "src/format/ReadLimits.h"
#include "src/volume/CubeSource.h"
#include "src/volume/GridRecord.h"
#include "vdb_bridge/DenseVolume.h"
#include "vdb_bridge/RawVolume.h"

namespace vdbdag::bridge {

struct DenseImportOptions {
    RawLayout raw;  // layout of .raw inputs (ignored for NRRD / MetaImage)
    // A header's detached data file must lie in the header's own folder
    // tree (no absolute path, no '..' out of it, no link that leads out)
    // unless this is set (`--allow-external-data`).
    bool allowExternalData = false;
    std::optional<double> backgroundBelow, backgroundAbove;
    // The value removed samples become (`--background-value`, e.g. -1000
    // HU); without it, their mean.
    std::optional<double> backgroundValue;
    bool showProgress = true;  // a Progress line on a terminal
    // DICOM: which series (`--series N|UID`); empty when the input holds one.
    std::string series;
    // DICOM: further files, folders or DICOMDIRs named beside the path,
    // scanned with it as one set (`encode a.dcm b.dcm ... -o x.ssvdag`).
    std::vector<std::string> moreInputs;
    // DICOM: drop the patient-identifying tags (name, ID, birth date,
    // institution, physicians, dates: DicomTags.h) from the grid's metadata
    // (`--drop-patient-tags`; by default every kept tag travels).
    bool dropPatientTags = false;
    // NIfTI or NRRD: which volume of a 4-D file (`--volume N`, 0-based).
    std::optional<int64_t> volume;
    // Set by importDense for the volumes of a 4-D file it reads in turn
    // (DenseVolume::resume); leave it null.
    std::shared_ptr<detail::InflateCheckpoints> resume;
    // A scalar scan's solid 8^3 blocks (all 512 samples kept, one value bit
    // for bit) become active tiles: one attribute entry each instead of 512
    // (detail/SolidBlocks.h). Off (`--no-tiles`): every voxel in its brick,
    // as a dense .vdb holds it.
    bool solidBlocks = true;
    // Read a scalar scan cube by cube (DenseImportResult::cubes): its
    // samples go once to a scratch file beside this path (ScratchFile.h)
    // instead of memory. Ignored for vector and colour scans.
    std::string cubesNear;
    // What the scan may make the import hold (`--max-voxels`, `--max-memory`
    // of `import`): its samples and what they become are weighed against
    // these, from the header, before any sample is read. `valueCopies`: the
    // caller's copies of every value beyond the grid record (`import` builds
    // an OpenVDB grid from it).
    format::ReadLimits limits = format::defaultReadLimits(1);
};

struct ThresholdReport {
    bool applied = false;
    uint64_t samples = 0;       // input samples
    uint64_t inactive = 0;      // samples turned into background
    uint64_t changed = 0;       // of those, samples whose value differs from the background
    double background = 0;      // the background value chosen
    double inputMin = 0, inputMax = 0;  // finite input range (peak = max - min)
    double maxAbsChange = 0, meanAbsChange = 0, rmsChange = 0;  // over all samples
    double psnr = 0;            // dB, peak = inputMax - inputMin; +inf when nothing changed
    unsigned storedBits = 0;    // integer scans: bits per stored sample, DICOM's Bits Stored when given (0 for float scans)
    double psnrStoredRange = 0; // dB, peak = the stored type's range (2^bits - 1, times the rescale slope)
    bool sharedBackground = false;  // both thresholds: the samples below and above became one background
    bool backgroundChosen = false;  // --background-value, not the mean
};

struct DenseImportResult {
    // One grid (a 4-D NIfTI file without --volume: one per volume); with
    // DenseImportOptions::cubesNear on a scalar scan, headers only, their
    // voxels in `cubes` (the same grids, read from the scratch file; the
    // same bricks and values as in memory, so the same encoded bytes).
    Volume volume;
    std::vector<std::unique_ptr<CubeSource>> cubes;
    DenseVolume source;
    ThresholdReport threshold;
};

// The header of `path`, by extension (see DenseVolume.h's denseFormatOf),
// its data file checked as DenseImportOptions::allowExternalData says.
// Only the layout, external-data, series and volume options are used.
DenseVolume describeDense(const std::string& path, const DenseImportOptions& options);

// Throws vdbdag::Error naming the file on any malformed header, missing or
// short data, unsupported type or bad threshold.
DenseImportResult importDense(const std::string& path, const DenseImportOptions& options);

// Where a grid imported from a scan came from and what its thresholds cost
// (DenseImport's metadata); nullopt for grids that did not come from a scan.
struct ScanProvenance {
    std::string sourceFile, format, sampleType, space;
    std::array<int64_t, 3> dims{0, 0, 0};
    std::optional<double> below, above;
    std::optional<ThresholdReport> threshold;  // inactive, changed, max and RMS change, PSNR (input range)
};
// The volumes of a 4-D NIfTI or NRRD file (its 4th dimension), 1 for any
// other scan. Throws vdbdag::Error naming the file.
int64_t volumeCountOf(const std::string& path);

std::optional<ScanProvenance> scanProvenanceOf(const GridRecord& grid);

} // namespace vdbdag::bridge
