// The options shared by `import` and `encode` for dense inputs (raw, NRRD,
// MetaImage, NIfTI, DICOM), parsed into app::DenseInputs (app/DenseInputs.h
// checks and resolves them), plus the text form of the threshold report
// (what making air background costs).
#pragma once
#include <string>

#include <CLI/CLI.hpp>

#include "app/DenseInputs.h"
#include "vdb_bridge/DenseImport.h"

namespace vdbdag::cli {

struct DenseInputOptions {
    app::DenseInputs values;  // the options' values, the optional ones set after parsing (inputs())
    void addTo(CLI::App& cmd);
    // The values, each optional one set when its option was given.
    app::DenseInputs inputs() const;

private:
    double below_ = 0, above_ = 0, backgroundValue_ = 0;
    int64_t volume_ = 0;
    CLI::Option *belowOption_ = nullptr, *aboveOption_ = nullptr, *backgroundValueOption_ = nullptr, *volumeOption_ = nullptr;
};

std::string thresholdText(const bridge::ThresholdReport& report);

} // namespace vdbdag::cli
