// See DicomTags.h. Identifying: the Basic Application Level Confidentiality
// Profile's patient, institution, physician and date attributes (DICOM
// PS3.15 Table E.1-1) among the kept tags.
#include "vdb_bridge/DicomTags.h"

#include <algorithm>

namespace vdbdag::bridge {

const std::vector<DicomTagSpec>& keptDicomTags() {
    static const std::vector<DicomTagSpec> tags{
        // patient, institution, physicians, dates (identifying)
        {"PatientName", 0x0010, 0x0010, true}, {"PatientID", 0x0010, 0x0020, true}, {"PatientBirthDate", 0x0010, 0x0030, true},
        {"PatientSex", 0x0010, 0x0040, true}, {"PatientAge", 0x0010, 0x1010, true}, {"PatientWeight", 0x0010, 0x1030, true},
        {"OtherPatientIDs", 0x0010, 0x1000, true}, {"InstitutionName", 0x0008, 0x0080, true}, {"ReferringPhysicianName", 0x0008, 0x0090, true},
        {"AccessionNumber", 0x0008, 0x0050, true}, {"StudyID", 0x0020, 0x0010, true}, {"StudyDate", 0x0008, 0x0020, true},
        {"StudyTime", 0x0008, 0x0030, true}, {"SeriesDate", 0x0008, 0x0021, true}, {"SeriesTime", 0x0008, 0x0031, true},
        {"AcquisitionDate", 0x0008, 0x0022, true}, {"StationName", 0x0008, 0x1010, true},
        // study and series
        {"StudyInstanceUID", 0x0020, 0x000D, false}, {"StudyDescription", 0x0008, 0x1030, false}, {"SeriesInstanceUID", 0x0020, 0x000E, false},
        {"SeriesNumber", 0x0020, 0x0011, false}, {"SeriesDescription", 0x0008, 0x103E, false}, {"Modality", 0x0008, 0x0060, false},
        {"SOPClassUID", 0x0008, 0x0016, false}, {"FrameOfReferenceUID", 0x0020, 0x0052, false}, {"Manufacturer", 0x0008, 0x0070, false},
        {"ManufacturerModelName", 0x0008, 0x1090, false}, {"BodyPartExamined", 0x0018, 0x0015, false}, {"ProtocolName", 0x0018, 0x1030, false},
        // geometry
        {"ImageOrientationPatient", 0x0020, 0x0037, false}, {"ImagePositionPatient", 0x0020, 0x0032, false}, {"PixelSpacing", 0x0028, 0x0030, false},
        {"SliceThickness", 0x0018, 0x0050, false}, {"SpacingBetweenSlices", 0x0018, 0x0088, false}, {"PatientPosition", 0x0018, 0x5100, false},
        // pixel encoding and display
        {"BitsAllocated", 0x0028, 0x0100, false}, {"BitsStored", 0x0028, 0x0101, false}, {"HighBit", 0x0028, 0x0102, false},
        {"PixelRepresentation", 0x0028, 0x0103, false}, {"PhotometricInterpretation", 0x0028, 0x0004, false},
        {"RescaleSlope", 0x0028, 0x1053, false}, {"RescaleIntercept", 0x0028, 0x1052, false}, {"RescaleType", 0x0028, 0x1054, false},
        {"WindowCenter", 0x0028, 0x1050, false}, {"WindowWidth", 0x0028, 0x1051, false},
        // acquisition
        {"KVP", 0x0018, 0x0060, false}, {"ConvolutionKernel", 0x0018, 0x1210, false}, {"MagneticFieldStrength", 0x0018, 0x0087, false},
        {"RepetitionTime", 0x0018, 0x0080, false}, {"EchoTime", 0x0018, 0x0081, false}, {"Units", 0x0054, 0x1001, false},
    };
    return tags;
}

std::vector<HeaderField> dicomTagsOf(const std::function<std::string(uint16_t, uint16_t)>& text) {
    std::vector<HeaderField> out;
    for (const DicomTagSpec& t : keptDicomTags()) {
        std::string value = text(t.group, t.element);
        if (!value.empty()) out.push_back({std::string("dicom_") + t.keyword, std::move(value)});
    }
    return out;
}

size_t dropIdentifyingDicomTags(std::vector<HeaderField>& fields) {
    const size_t before = fields.size();
    std::erase_if(fields, [](const HeaderField& f) {
        for (const DicomTagSpec& t : keptDicomTags())
            if (t.identifying && f.key == std::string("dicom_") + t.keyword) return true;
        return false;
    });
    return before - fields.size();
}

} // namespace vdbdag::bridge
