// See DenseInputs.h.
#include "app/DenseInputs.h"

#include <array>

#include "src/util/Error.h"

namespace vdbdag::app {

bool DenseInputs::anyGiven() const {
    return !dims.empty() || !type.empty() || !endian.empty() || !spacing.empty() || !origin.empty() || !series.empty() || below || above ||
           backgroundValue || volume || dropPatientTags || noTiles;
}

std::string DenseInputs::takeInputs(const std::vector<std::string>& inputs) {
    if (inputs.empty()) throw Error("no input given");
    moreInputs.assign(inputs.begin() + 1, inputs.end());
    if (!moreInputs.empty())
        for (const std::string& in : inputs)
            if (bridge::denseFormatOf(in) != bridge::DenseFormat::Dicom)
                throw Error(in + ": not DICOM; several inputs are read as one set of DICOM files, folders or DICOMDIRs only");
    return inputs.front();
}

void DenseInputs::checkApplies(const std::string& path) const {
    if (bridge::denseFormatOf(path) != bridge::DenseFormat::None) return;
    if (!series.empty()) throw Error(path + ": --series applies to DICOM inputs only (a folder, a .dcm file or a DICOMDIR)");
    if (anyGiven())
        throw Error(path + ": the dense-scan options (--dims, --type, --endian, --spacing, --origin, --background-below/above/value, --volume, "
                           "--drop-patient-tags, --no-tiles) apply to .raw/.nrrd/.nhdr/.mhd/.mha/.nii/DICOM inputs only");
}

bridge::DenseImportOptions DenseInputs::resolve(const std::string& path) const {
    bridge::DenseImportOptions o;
    o.moreInputs = moreInputs;
    const bridge::DenseFormat format = bridge::denseFormatOf(path);
    if (format != bridge::DenseFormat::Raw && (!dims.empty() || !type.empty() || !endian.empty() || !spacing.empty() || !origin.empty()))
        throw Error(path + ": --dims/--type/--endian/--spacing/--origin apply to .raw inputs only (this file has a header)");
    const auto three = [&](size_t n, const char* option) {
        if (n != 0 && n != 3) throw Error(path + ": " + option + " takes 3 numbers (x y z)");
    };
    three(dims.size(), "--dims"), three(spacing.size(), "--spacing"), three(origin.size(), "--origin");
    if (!dims.empty()) o.raw.dims = std::array<int64_t, 3>{dims[0], dims[1], dims[2]};
    if (!type.empty()) o.raw.type = bridge::parseSampleType(type, path);
    if (!endian.empty() && endian != "little" && endian != "big") throw Error(path + ": --endian is little or big, not '" + endian + "'");
    if (!endian.empty()) o.raw.bigEndian = endian == "big";
    if (!spacing.empty()) o.raw.spacing = {spacing[0], spacing[1], spacing[2]};
    if (!origin.empty()) o.raw.origin = {origin[0], origin[1], origin[2]};
    if (!series.empty()) {
        if (format != bridge::DenseFormat::Dicom) throw Error(path + ": --series applies to DICOM inputs only (a folder, a .dcm file or a DICOMDIR)");
        o.series = series;
    }
    o.backgroundBelow = below, o.backgroundAbove = above, o.backgroundValue = backgroundValue;
    o.allowExternalData = allowExternalData;
    o.solidBlocks = !noTiles;
    if (dropPatientTags && format != bridge::DenseFormat::Dicom)
        throw Error(path + ": --drop-patient-tags applies to DICOM inputs only (a folder, a .dcm file or a DICOMDIR)");
    o.dropPatientTags = dropPatientTags;
    if (volume) {
        if (format != bridge::DenseFormat::Nifti && format != bridge::DenseFormat::Nrrd) throw Error(path + ": --volume applies to 4-D NIfTI and NRRD inputs only");
        if (*volume < 0) throw Error(path + ": --volume counts from 0");
        o.volume = volume;
    }
    return o;
}

std::vector<std::string> denseInputFiles(const std::string& input, const DenseInputs& options) {
    const bridge::DenseFormat format = bridge::denseFormatOf(input);
    if (format == bridge::DenseFormat::None || format == bridge::DenseFormat::Raw) return {input};
    const bridge::DenseImportOptions resolved = options.resolve(input);
    const bridge::DenseVolume header = bridge::describeDense(input, resolved);
    if (format != bridge::DenseFormat::Dicom) return {input, header.dataPath};
    std::vector<std::string> files{input};
    files.insert(files.end(), options.moreInputs.begin(), options.moreInputs.end());
    for (const bridge::DicomSlice& s : header.slices)
        if (files.back() != s.file) files.push_back(s.file);  // frames of one file are listed once
    return files;
}

} // namespace vdbdag::app
