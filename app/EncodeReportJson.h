// The JSON parts of an encode's report that `encode` and `info` share: a
// grid's colour quantisation (--colour-bits), its normals (--normals) and a
// dense scan's background threshold (--background-below/above).
#pragma once
#include <nlohmann/json.hpp>

#include "src/format/SsvdagFile.h"
#include "vdb_bridge/DenseImport.h"

namespace vdbdag::app {

// `grid` must have colours (normals).
nlohmann::json colourJson(const format::EncodedGrid& grid);
nlohmann::json normalsJson(const format::EncodedGrid& grid);
// null when no threshold was applied.
nlohmann::json thresholdJson(const bridge::ThresholdReport& report);

} // namespace vdbdag::app
