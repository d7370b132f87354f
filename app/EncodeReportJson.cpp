// See EncodeReportJson.h.
#include "app/EncodeReportJson.h"

#include <cmath>

#include "src/attributes/PaletteCompressor.h"

namespace vdbdag::app {

nlohmann::json colourJson(const format::EncodedGrid& grid) {
    const attributes::ColourReport& c = *grid.colour;
    return {{"name", grid.record.name}, {"bits", c.bits}, {"entries", c.entries}, {"distinct_before", c.distinctBefore},
            {"distinct_after", c.distinctAfter}, {"changed", c.changed}, {"mean_abs_error_rgb", c.meanAbsError},
            {"max_abs_error_rgb", c.maxAbsError}, {"mean_delta_e94", c.meanDeltaE94}, {"max_delta_e94", c.maxDeltaE94}};
}

nlohmann::json normalsJson(const format::EncodedGrid& grid) {
    const attributes::NormalChannel& n = *grid.normals;
    const std::vector<uint8_t> codes = n.codes.decodeAll();
    return {{"name", grid.record.name}, {"bits", n.bits},
            {"source", n.report.source == attributes::NormalReport::Source::Gradient ? "gradient" : "normal grid"},
            {"entries", n.report.entries}, {"zero_length", n.report.zeroLength}, {"one_sided", n.report.oneSided},
            {"mean_angle_degrees", n.report.meanAngleDegrees}, {"max_angle_degrees", n.report.maxAngleDegrees},
            {"distinct_codes", attributes::channelStats(codes, 4, n.codes).unique}, {"palette_bytes", n.codes.byteSize()}};
}

nlohmann::json thresholdJson(const bridge::ThresholdReport& r) {
    if (!r.applied) return nullptr;
    return {{"samples", r.samples},
            {"inactive_samples", r.inactive},
            {"changed_samples", r.changed},
            {"background_value", r.background},
            {"input_min", r.inputMin},
            {"input_max", r.inputMax},
            {"max_abs_change", r.maxAbsChange},
            {"mean_abs_change", r.meanAbsChange},
            {"rms_change", r.rmsChange},
            {"psnr_db", std::isfinite(r.psnr) ? nlohmann::json(r.psnr) : nlohmann::json(nullptr)},
            {"psnr_peak", "input range"},
            {"stored_bits", r.storedBits},
            {"psnr_stored_range_db", r.storedBits && std::isfinite(r.psnrStoredRange) ? nlohmann::json(r.psnrStoredRange) : nlohmann::json(nullptr)},
            {"background_is", r.backgroundChosen ? "chosen" : "mean of removed samples"},
            {"shared_background", r.sharedBackground}};
}

} // namespace vdbdag::app
