// Builds the `info` report (text and JSON) of an encoded scene: per grid its
// header (what vdb_print shows), the per-level node counts (SVO, SVDAG,
// stored DAG), bytes per section and bits per active voxel. Shared by `info`
// on .ssvdag files and on .vdb files (which are encoded in memory first).
#pragma once
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include <nlohmann/json.hpp>

#include "src/format/GridSummary.h"
#include "src/format/SsvdagFile.h"
#include "vdb_bridge/VdbSummary.h"

namespace vdbdag::app {

// `encodedBytes`: the scene as a .ssvdag (the file read, or the encoding of
// a .vdb). With `valueStats`, each value channel's statistics (Dado et al.'s
// Table 1) and the traceable size, which decode every value and rebuild the
// palettes; without, nothing is decoded but the value windows' range.
nlohmann::json sceneReport(const format::SsvdagScene& scene, std::span<const uint8_t> encodedBytes, const std::string& name, bool valueStats);
// The same of a file read in part (ReadOptions::headersOnly): its section
// table, its size, and how many windows of each coding a grid's
// PredictedWindows (or InactivePredictedWindows) section holds.
struct StoredScene {
    std::vector<format::SectionSummary> sections;
    uint64_t bytes = 0;
    std::function<std::vector<uint64_t>(uint32_t grid, bool inactive)> codings;
};
nlohmann::json sceneReport(const format::SsvdagScene& scene, const StoredScene& file, const std::string& name, bool valueStats);
std::string formatSceneReport(const nlohmann::json& report);

// What `vdb_print -l -m` shows of a grid (see vdb_bridge/VdbSummary.h), as
// JSON keys of the grid's report, and as text.
void addGridHeader(nlohmann::json& grid, const GridRecord& header, const bridge::GridHeaderFacts& facts, const format::GridSummary& summary, bool fromVdb);
std::string formatGridHeader(const nlohmann::json& grid);
nlohmann::json metadataJson(const std::vector<bridge::MetadataEntry>& entries);

// The colour (--colour-bits) and normal (--normals) parts of a grid's
// report (app/EncodeReportJson.h), as text.
std::string formatColour(const nlohmann::json& colour);
std::string formatNormals(const nlohmann::json& normals);

} // namespace vdbdag::app
