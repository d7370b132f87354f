// See DenseInputOptions.h.
#include "cli/DenseInputOptions.h"

#include <cmath>

#include <fmt/core.h>

#include "cli/FiniteNumber.h"
#include "src/util/Error.h"

namespace vdbdag::cli {

void DenseInputOptions::addTo(CLI::App& cmd) {
    cmd.add_option("--dims", dims, "raw input: samples along x y z (x fastest)")->expected(3);
    cmd.add_option("--type", type, "raw input: sample type u8|i8|u16|i16|u32|i32|f32|f64");
    cmd.add_option("--endian", endian, "raw input: little (default) or big")->check(CLI::IsMember({"little", "big"}));
    cmd.add_option("--spacing", spacing, "raw input: voxel spacing sx sy sz (default 1 1 1)")->expected(3);
    cmd.add_option("--origin", origin, "raw input: world position of sample (0,0,0) (default 0 0 0)")->expected(3);
    cmd.add_option("--series", series, "DICOM input: the series to read, by its number in `vdbdag info` or its Series Instance UID");
    belowOption = cmd.add_option("--background-below", below, "dense input: samples below V become inactive background (lossy; the cost is reported)")
                      ->check(finiteNumber());
    aboveOption = cmd.add_option("--background-above", above, "dense input: samples above V become inactive background (lossy; the cost is reported)")
                      ->check(finiteNumber());
    backgroundValueOption =
        cmd.add_option("--background-value", backgroundValue, "dense input: the value removed samples become (default: their mean)")->check(finiteNumber());
    volumeOption = cmd.add_option("--volume", volume, "4-D NIfTI or NRRD input: which volume (0-based; without it, one grid per volume)")->check(CLI::NonNegativeNumber);
    cmd.add_flag("--drop-patient-tags", dropPatientTags,
                 "DICOM input: leave the patient-identifying tags (name, ID, birth date, institution, physicians, dates) out of the grid's "
                 "metadata (by default they are kept with the series' other tags)");
    cmd.add_flag("--allow-external-data", allowExternalData,
                 "dense header: read a data file outside the header's folder (an absolute path, '..', or a link leading out)");
}

std::string DenseInputOptions::takeInputs(const std::vector<std::string>& inputs) {
    if (inputs.empty()) throw Error("no input given");
    moreInputs.assign(inputs.begin() + 1, inputs.end());
    if (!moreInputs.empty())
        for (const std::string& in : inputs)
            if (bridge::denseFormatOf(in) != bridge::DenseFormat::Dicom)
                throw Error(in + ": not DICOM; several inputs are read as one set of DICOM files, folders or DICOMDIRs only");
    return inputs.front();
}

bridge::DenseImportOptions DenseInputOptions::resolve(const std::string& path) const {
    bridge::DenseImportOptions o;
    o.moreInputs = moreInputs;
    const bool rawInput = bridge::denseFormatOf(path) == bridge::DenseFormat::Raw;
    if (!rawInput && (!dims.empty() || !type.empty() || !endian.empty() || !spacing.empty() || !origin.empty()))
        throw Error(path + ": --dims/--type/--endian/--spacing/--origin apply to .raw inputs only (this file has a header)");
    if (!dims.empty()) o.raw.dims = std::array<int64_t, 3>{dims[0], dims[1], dims[2]};
    if (!type.empty()) o.raw.type = bridge::parseSampleType(type, path);
    if (!endian.empty()) o.raw.bigEndian = endian == "big";
    if (!spacing.empty()) o.raw.spacing = {spacing[0], spacing[1], spacing[2]};
    if (!origin.empty()) o.raw.origin = {origin[0], origin[1], origin[2]};
    if (!series.empty()) {
        if (bridge::denseFormatOf(path) != bridge::DenseFormat::Dicom)
            throw Error(path + ": --series applies to DICOM inputs only (a folder, a .dcm file or a DICOMDIR)");
        o.series = series;
    }
    if (belowOption && belowOption->count()) o.backgroundBelow = below;
    if (aboveOption && aboveOption->count()) o.backgroundAbove = above;
    if (backgroundValueOption && backgroundValueOption->count()) o.backgroundValue = backgroundValue;
    o.allowExternalData = allowExternalData;
    if (dropPatientTags && bridge::denseFormatOf(path) != bridge::DenseFormat::Dicom)
        throw Error(path + ": --drop-patient-tags applies to DICOM inputs only (a folder, a .dcm file or a DICOMDIR)");
    o.dropPatientTags = dropPatientTags;
    if (volumeOption && volumeOption->count()) {
        if (bridge::denseFormatOf(path) != bridge::DenseFormat::Nifti && bridge::denseFormatOf(path) != bridge::DenseFormat::Nrrd)
            throw Error(path + ": --volume applies to 4-D NIfTI and NRRD inputs only");
        o.volume = volume;
    }
    return o;
}

std::string thresholdText(const bridge::ThresholdReport& r) {
    if (!r.applied) return "";
    auto db = [](double x) { return std::isfinite(x) ? fmt::format("{:.2f} dB", x) : std::string("inf (lossless)"); };
    std::string text = fmt::format("  background {} ({}): {} of {} samples inactive ({:.1f}%), {} changed; max |change| {:.6g}, mean {:.6g}, RMS {:.6g}; "
                                   "PSNR {} (peak = input range {:.6g}..{:.6g})",
                                   r.background, r.backgroundChosen ? "--background-value" : "mean of the removed samples", r.inactive, r.samples,
                                   r.samples ? 100.0 * double(r.inactive) / double(r.samples) : 0.0, r.changed, r.maxAbsChange, r.meanAbsChange,
                                   r.rmsChange, db(r.psnr), r.inputMin, r.inputMax);
    if (r.storedBits) text += fmt::format(", {} (peak = the {}-bit stored range)", db(r.psnrStoredRange), r.storedBits);
    text += "\n";
    if (r.sharedBackground)
        text += "  note: the samples below and above the thresholds became one background value; a decode gives both back as that value\n";
    return text;
}

} // namespace vdbdag::cli

namespace vdbdag::cli {

std::vector<std::string> denseInputFiles(const std::string& input, const DenseInputOptions& options) {
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

} // namespace vdbdag::cli
