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

// `inputs`: folders, files and DICOMDIRs, scanned as one set (a file named
// twice is read once). Throws vdbdag::Error naming the input when nothing
// there can be read.
DicomScan scanDicom(const std::vector<std::string>& inputs);

// The series `choice` names (its 1-based number in scanDicom's list, or its
// UID); an empty choice is allowed only when there is exactly one series,
// otherwise the error lists them. Throws vdbdag::Error. For more than one
// input the grid is named after the first input's folder.
DenseVolume describeDicomSeries(const std::vector<std::string>& inputs, const std::string& choice);

inline DicomScan scanDicom(const std::string& input) { return scanDicom(std::vector<std::string>{input}); }
inline DenseVolume describeDicomSeries(const std::string& input, const std::string& choice) {
    return describeDicomSeries(std::vector<std::string>{input}, choice);
}

// How messages name a set of inputs: the input, or "FIRST (and N more inputs)".
std::string dicomInputName(const std::vector<std::string>& inputs);

// Reads the series' slices (DenseVolume::slices) in order, decoding any
// transfer syntax GDCM decodes. Throws vdbdag::Error naming the slice file.
std::unique_ptr<SliceReader> openDicomSlices(const DenseVolume& volume);

} // namespace vdbdag::bridge
