// The DICOM tags a series keeps in its grid's metadata: what identifies the
// series, describes the acquisition and gives the geometry and the pixel
// encoding, read from the series' first file as text ("dicom_" + the
// keyword, e.g. dicom_SeriesInstanceUID, dicom_PixelSpacing "0.5\0.5").
// The patient's identity (name, ID, birth date, …), the institution, the
// physicians and the study dates are kept too unless the user asks to drop
// them (`encode --drop-patient-tags`). docs/SCAN_METADATA.md lists them.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vdb_bridge/DenseVolume.h"

namespace vdbdag::bridge {

struct DicomTagSpec {
    const char* keyword;
    uint16_t group, element;
    bool identifying;  // dropped by --drop-patient-tags
};
const std::vector<DicomTagSpec>& keptDicomTags();

// `text(group, element)`: the element's value as text, empty when absent.
std::vector<HeaderField> dicomTagsOf(const std::function<std::string(uint16_t, uint16_t)>& text);
// Removes the identifying tags' fields (dicom_* keys only); returns how many.
size_t dropIdentifyingDicomTags(std::vector<HeaderField>& fields);

} // namespace vdbdag::bridge
