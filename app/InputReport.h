// What `vdbdag info` says of an input, as a library call: a .ssvdag file
// (reading only what it prints: header, DAG, section table, the value
// windows' range), a .vdb file (OpenVDB's own figures, then the encoding in
// memory, with the plain-SVDAG reduction run too so all three node counts
// show), a NanoVDB file, a scan's header (what `encode` would make of it) or
// the series of DICOM input (what `encode --series N|UID` picks from, and
// the files skipped). Each as the report `info --json` prints and its text.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "src/format/ReadLimits.h"

namespace vdbdag::app {

struct InfoRequest {
    bool noSymmetry = false;     // a .vdb's or .nvdb's encoding in memory: the plain SVDAG
    bool values = false;         // a .ssvdag's value channels' statistics (decodes every value)
    format::ReadLimits limits;   // what a .ssvdag may expand to
};

// One input (not DICOM): its report and its text. Throws vdbdag::Error
// naming the input when it cannot be read.
std::pair<nlohmann::json, std::string> describeInput(const InfoRequest& request, const std::string& input);

// DICOM input (folders, .dcm files, DICOMDIRs read as one set): the series
// found and the files skipped, and its text.
std::pair<nlohmann::json, std::string> describeDicom(const std::vector<std::string>& inputs);

} // namespace vdbdag::app
