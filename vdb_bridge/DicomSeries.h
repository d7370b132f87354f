// DICOM input (GDCM): a folder (searched recursively), a list of files or a
// DICOMDIR is scanned into series (Series Instance UID, split further by
// orientation and slice size); one series becomes a DenseVolume whose
// slices are ordered by their position along the slice normal (Image
// Position Patient . normal), never by file name or instance number.
// Geometry is in LPS (DICOM's patient space); Rescale Slope/Intercept go to
// DenseVolume::rescaleSlope/rescaleIntercept, applied by DenseImport.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge {

struct DicomSeriesInfo {
    std::string uid;          // Series Instance UID (0020,000E)
    std::string modality;     // (0008,0060)
    std::string description;  // Series Description (0008,103E)
    int64_t seriesNumber = 0; // (0020,0011)
    std::array<int64_t, 3> dims{0, 0, 0};       // columns, rows, slices (missing slices included)
    int64_t missingSlices = 0;                  // empty slots where the stack lacks a slice
    std::array<double, 3> spacing{1, 1, 1};     // column, row, slice spacing (mm)
    std::string sampleType;   // "u16", ... (sampleTypeName)
    std::vector<std::string> notes;  // e.g. uneven spacing, duplicates
    // Why describeDicomSeries refuses this series (duplicate positions, gaps,
    // uneven spacing, mixed rescales, colour samples...); empty when it converts.
    std::string problem;
};

struct DicomScan {
    std::vector<DicomSeriesInfo> series;  // listing order: by series number, then UID
    std::vector<std::string> skipped;     // "FILE: why" for files that are not DICOM images (non-DICOM, SEG, SR, ...)
};

// Throws vdbdag::Error naming the path when nothing there can be read.
DicomScan scanDicom(const std::string& path);

// The series `choice` names (its 1-based number in scanDicom's list, or its
// UID); an empty choice is allowed only when there is exactly one series,
// otherwise the error lists them. Throws vdbdag::Error.
DenseVolume describeDicomSeries(const std::string& path, const std::string& choice);

// Reads the series' slices (DenseVolume::slices) in order, decoding any
// transfer syntax GDCM decodes. Throws vdbdag::Error naming the slice file.
std::unique_ptr<SliceReader> openDicomSlices(const DenseVolume& volume);

} // namespace vdbdag::bridge
