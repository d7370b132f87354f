// Builds the `info` report (text and JSON) of an encoded scene: per grid the
// per-level node counts (SVO, SVDAG, stored DAG), bytes per section and bits
// per active voxel. Shared by `info` on .ssvdag files and on .vdb files
// (which are encoded in memory first).
#pragma once
#include <cstdint>
#include <span>
#include <string>

#include <nlohmann/json.hpp>

#include "src/format/SsvdagFile.h"

namespace vdbdag::cli {

nlohmann::json sceneReport(const format::SsvdagScene& scene, std::span<const uint8_t> fileBytes, const std::string& name);
std::string formatSceneReport(const nlohmann::json& report);

// The colour (--colour-bits) and normal (--normals) parts of a grid's
// report, shared by `encode` and `info`; `grid` must have them.
nlohmann::json colourJson(const format::EncodedGrid& grid);
nlohmann::json normalsJson(const format::EncodedGrid& grid);
std::string formatColour(const nlohmann::json& colour);
std::string formatNormals(const nlohmann::json& normals);

} // namespace vdbdag::cli
