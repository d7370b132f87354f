// The options shared by `import` and `encode` for dense inputs (raw, NRRD,
// MetaImage): the raw layout (--dims, --type, --endian, --spacing, --origin)
// and the background thresholds, plus the text/JSON form of the threshold
// report (what making air background costs).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "vdb_bridge/DenseImport.h"

namespace vdbdag::cli {

struct DenseInputOptions {
    std::vector<int64_t> dims;
    std::string type, endian;
    std::string series;  // DICOM input: --series N|UID
    std::vector<double> spacing, origin;
    double below = 0, above = 0;
    bool allowExternalData = false, dropPatientTags = false;
    int64_t volume = 0;
    CLI::Option* volumeOption = nullptr;
    CLI::Option* belowOption = nullptr;
    CLI::Option* aboveOption = nullptr;
    double backgroundValue = 0;
    CLI::Option* backgroundValueOption = nullptr;
    std::vector<std::string> moreInputs;  // DICOM: the inputs after the first

    void addTo(CLI::App& cmd);
    // The command's positional inputs: the first is the input; more than one
    // are allowed for DICOM only (files, folders, DICOMDIRs scanned as one
    // set). Throws vdbdag::Error naming the input that is not DICOM.
    std::string takeInputs(const std::vector<std::string>& inputs);
    // Throws vdbdag::Error naming `path` for inconsistent values.
    bridge::DenseImportOptions resolve(const std::string& path) const;
};

// The files a command reads for `input`: the input itself and, for a dense
// header (.nhdr, .mhd), the data file it names, for DICOM every slice file of
// the series (an output must be none of them).
std::vector<std::string> denseInputFiles(const std::string& input, const DenseInputOptions& options);

std::string thresholdText(const bridge::ThresholdReport& report);

} // namespace vdbdag::cli
