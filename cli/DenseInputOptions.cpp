// See DenseInputOptions.h.
#include "cli/DenseInputOptions.h"

#include <cmath>

#include <fmt/core.h>

#include "cli/FiniteNumber.h"
#include "src/util/Error.h"

namespace vdbdag::cli {

void DenseInputOptions::addTo(CLI::App& cmd) {
    app::DenseInputs& v = values;
    cmd.add_option("--dims", v.dims, "raw input: samples along x y z (x fastest)")->expected(3);
    cmd.add_option("--type", v.type, "raw input: sample type u8|i8|u16|i16|u32|i32|f32|f64");
    cmd.add_option("--endian", v.endian, "raw input: little (default) or big")->check(CLI::IsMember({"little", "big"}));
    cmd.add_option("--spacing", v.spacing, "raw input: voxel spacing sx sy sz (default 1 1 1)")->expected(3);
    cmd.add_option("--origin", v.origin, "raw input: world position of sample (0,0,0) (default 0 0 0)")->expected(3);
    cmd.add_option("--series", v.series, "DICOM input: the series to read, by its number in `vdbdag info` or its Series Instance UID");
    belowOption_ = cmd.add_option("--background-below", below_, "dense input: samples below V become inactive background (lossy; the cost is reported)")
                       ->check(finiteNumber());
    aboveOption_ = cmd.add_option("--background-above", above_, "dense input: samples above V become inactive background (lossy; the cost is reported)")
                       ->check(finiteNumber());
    backgroundValueOption_ =
        cmd.add_option("--background-value", backgroundValue_, "dense input: the value removed samples become (default: their mean)")->check(finiteNumber());
    volumeOption_ = cmd.add_option("--volume", volume_, "4-D NIfTI or NRRD input: which volume (0-based; without it, one grid per volume)")->check(CLI::NonNegativeNumber);
    cmd.add_flag("--drop-patient-tags", v.dropPatientTags,
                 "DICOM input: leave the patient-identifying tags (name, ID, birth date, institution, physicians, dates) out of the grid's "
                 "metadata (by default they are kept with the series' other tags)");
    cmd.add_flag("--no-tiles", v.noTiles,
                 "dense input: keep every voxel in its 4^3 brick (by default an 8^3 block of one value becomes a tile, one stored value: "
                 "a label atlas's regions, a zero background)");
    cmd.add_flag("--allow-external-data", v.allowExternalData,
                 "dense header: read a data file outside the header's folder (an absolute path, '..', or a link leading out)");
}

app::DenseInputs DenseInputOptions::inputs() const {
    app::DenseInputs v = values;
    if (belowOption_ && belowOption_->count()) v.below = below_;
    if (aboveOption_ && aboveOption_->count()) v.above = above_;
    if (backgroundValueOption_ && backgroundValueOption_->count()) v.backgroundValue = backgroundValue_;
    if (volumeOption_ && volumeOption_->count()) v.volume = volume_;
    return v;
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
