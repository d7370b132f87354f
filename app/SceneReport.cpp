// See SceneReport.h.
#include "app/SceneReport.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include <fmt/core.h>

#include "app/EncodeReportJson.h"
#include "src/attributes/PaletteCompressor.h"
#include "src/attributes/PredictedWindows.h"
#include "src/encoding/AttributeLayout.h"
#include "src/format/TraceableValues.h"
#include "vdb_bridge/DenseImport.h"

namespace vdbdag::app {

std::string formatColour(const nlohmann::json& c) {
    const auto mean = c["mean_abs_error_rgb"], max = c["max_abs_error_rgb"];
    return fmt::format("colours of '{}' ({} bits): {} -> {} distinct, {} of {} values changed; abs error R/G/B (0..255) mean {:.2f}/{:.2f}/{:.2f}, "
                       "max {:.2f}/{:.2f}/{:.2f}; ΔE94 mean {:.3f}, max {:.3f}",
                       c["name"].get<std::string>(), c["bits"].get<unsigned>(), c["distinct_before"].get<uint64_t>(), c["distinct_after"].get<uint64_t>(),
                       c["changed"].get<uint64_t>(), c["entries"].get<uint64_t>(), mean[0].get<double>(), mean[1].get<double>(), mean[2].get<double>(),
                       max[0].get<double>(), max[1].get<double>(), max[2].get<double>(), c["mean_delta_e94"].get<double>(), c["max_delta_e94"].get<double>());
}

std::string formatNormals(const nlohmann::json& n) {
    return fmt::format("normals of '{}' ({}-bit ONV from the {}): {} entries, {} distinct codes, {} palette bytes; {} without direction (+z), "
                       "{} one-sided at the band edge; angular error mean {:.4f}°, max {:.4f}°",
                       n["name"].get<std::string>(), n["bits"].get<unsigned>(), n["source"].get<std::string>(), n["entries"].get<uint64_t>(),
                       n["distinct_codes"].get<uint64_t>(), n["palette_bytes"].get<uint64_t>(), n["zero_length"].get<uint64_t>(),
                       n["one_sided"].get<uint64_t>(), n["mean_angle_degrees"].get<double>(), n["max_angle_degrees"].get<double>());
}

nlohmann::json metadataJson(const std::vector<bridge::MetadataEntry>& entries) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& e : entries) out[e.name] = {{"type", e.type}, {"value", e.value}};
    return out;
}

void addGridHeader(nlohmann::json& j, const GridRecord& header, const bridge::GridHeaderFacts& facts, const format::GridSummary& summary, bool fromVdb) {
    using nlohmann::json;
    const ValueType type = header.valueType;
    j["tree_type"] = facts.treeType;
    j["voxel_size"] = facts.voxelSize;
    j["transform"] = facts.transform;
    j["index_to_world"] = header.indexToWorld;
    j[fromVdb ? "active_tiles" : "solid_nodes"] = summary.solidNodes;
    if (summary.indexBox) {
        const auto& b = *summary.indexBox;
        j["index_bbox"] = {{"min", b.min}, {"max", b.max}};
    } else {
        j["index_bbox"] = nullptr;
    }
    if (facts.worldBox) {
        const auto& w = *facts.worldBox;
        j["world_bbox"] = {{"min", {w[0], w[1], w[2]}}, {"max", {w[3], w[4], w[5]}}};
    } else {
        j["world_bbox"] = nullptr;
    }
    auto value = [&](std::span<const uint8_t> v) {
        const std::vector<double> n = format::valueNumbers(type, v);
        return n.size() == 1 ? json(n[0]) : json(n);
    };
    auto text = [&](std::span<const uint8_t> v) { return format::formatValue(type, v); };
    if (!header.background.empty()) {
        j["background"] = value(header.background);
        j["background_text"] = text(header.background);
    }
    if (!summary.activeRange.min.empty())
        j["value_range"] = {{"min", value(summary.activeRange.min)}, {"max", value(summary.activeRange.max)},
                            {"min_text", text(summary.activeRange.min)}, {"max_text", text(summary.activeRange.max)}};
    else
        j["value_range"] = nullptr;
    j["metadata"] = metadataJson(facts.metadata);
}

std::string formatGridHeader(const nlohmann::json& g) {
    std::string out = fmt::format("  tree {}, voxel size {:.6g} x {:.6g} x {:.6g} ({})\n", g["tree_type"].get<std::string>(), g["voxel_size"][0].get<double>(),
                                  g["voxel_size"][1].get<double>(), g["voxel_size"][2].get<double>(), g["transform"].get<std::string>());
    if (!g["index_bbox"].is_null()) {
        const auto& b = g["index_bbox"];
        auto c = [&](const char* k, int a) { return b[k][a].get<int64_t>(); };
        out += fmt::format("  index bbox [{}, {}, {}] -> [{}, {}, {}] ({} x {} x {})\n", c("min", 0), c("min", 1), c("min", 2), c("max", 0), c("max", 1),
                           c("max", 2), c("max", 0) - c("min", 0) + 1, c("max", 1) - c("min", 1) + 1, c("max", 2) - c("min", 2) + 1);
    }
    if (!g["world_bbox"].is_null()) {
        const auto& w = g["world_bbox"];
        out += fmt::format("  world bbox [{:.6g}, {:.6g}, {:.6g}] -> [{:.6g}, {:.6g}, {:.6g}]\n", w["min"][0].get<double>(), w["min"][1].get<double>(),
                           w["min"][2].get<double>(), w["max"][0].get<double>(), w["max"][1].get<double>(), w["max"][2].get<double>());
    }
    if (g.contains("background_text")) out += fmt::format("  background {}\n", g["background_text"].get<std::string>());
    if (!g["value_range"].is_null())
        out += fmt::format("  active values from {} to {}\n", g["value_range"]["min_text"].get<std::string>(), g["value_range"]["max_text"].get<std::string>());
    const auto& m = g["index_to_world"];
    out += "  index to world";
    for (int r = 0; r < 4; ++r)
        out += fmt::format(" [{:.6g}, {:.6g}, {:.6g}, {:.6g}]", m[4 * r].get<double>(), m[4 * r + 1].get<double>(), m[4 * r + 2].get<double>(), m[4 * r + 3].get<double>());
    out += "\n";
    // A source header's fields (nifti_*, dicom_*, nrrd_*, mha_tag_*:
    // docs/SCAN_METADATA.md) as one line per header, with the few a reader
    // looks for; --json lists every one.
    struct HeaderGroup {
        const char* prefix;
        const char* what;
        std::vector<std::string> shown;
        size_t count = 0;
        std::string summary;
    };
    HeaderGroup groups[] = {{"nifti_", "NIfTI header fields", {"nifti_version", "nifti_qform_code", "nifti_sform_code", "nifti_intent_code", "nifti_descrip"}, 0, {}},
                            {"dicom_", "DICOM tags", {"dicom_Modality", "dicom_SeriesDescription", "dicom_SeriesInstanceUID"}, 0, {}},
                            {"nrrd_", "NRRD fields and key/value pairs", {}, 0, {}},
                            {"mha_tag_", "MetaImage tags", {}, 0, {}}};
    for (const auto& [name, e] : g["metadata"].items()) {
        HeaderGroup* group = nullptr;
        for (HeaderGroup& h : groups)
            if (name.rfind(h.prefix, 0) == 0) group = &h;
        if (!group) {
            out += fmt::format("  metadata {}: {}\n", name, e["value"].get<std::string>());
            continue;
        }
        ++group->count;
        if (std::find(group->shown.begin(), group->shown.end(), name) != group->shown.end())
            group->summary += fmt::format(", {} {}", name.substr(std::string(group->prefix).size()), e["value"].get<std::string>());
    }
    for (const HeaderGroup& h : groups)
        if (h.count) out += fmt::format("  metadata {}*: {} {}{} (--json lists them)\n", h.prefix, h.count, h.what, h.summary);
    return out;
}

nlohmann::json sceneReport(const format::SsvdagScene& scene, std::span<const uint8_t> fileBytes, const std::string& name, bool valueStats) {
    StoredScene file{format::summarizeContainer(fileBytes, name), fileBytes.size(), [&](uint32_t g, bool inactive) -> std::vector<uint64_t> {
                         const format::EncodedGrid& grid = scene.grids[g];
                         const format::EncodedLayer& layer = grid.layer(inactive);
                         const attributes::ValueWindowsPayload& w = layer.valueWindows;
                         if (!w.predicted || w.empty()) return {};
                         return attributes::predictedWindowCodings(w.load(), valueSize(grid.record.valueType), encoding::attributeLayout(layer.dag),
                                                                   "grid '" + grid.record.name + "' predicted windows");
                     }};
    return sceneReport(scene, file, name, valueStats);
}

nlohmann::json sceneReport(const format::SsvdagScene& scene, const StoredScene& file, const std::string& name, bool valueStats) {
    using nlohmann::json;
    const auto& sections = file.sections;
    json report{{"input", name}, {"ssvdag_bytes", file.bytes}, {"grid_count", scene.grids.size()}, {"grids", json::array()}};
    uint64_t fileLevelBytes = file.bytes;
    for (size_t g = 0; g < scene.grids.size(); ++g) {
        const format::EncodedGrid& grid = scene.grids[g];
        json j{{"index", g},
               {"name", grid.record.name},
               {"class", grid.record.gridClass},
               {"value_type", valueTypeName(grid.record.valueType)},
               {"active_voxels", grid.active.voxels},
               {"encoding", grid.symmetry ? "SSVDAG" : "SVDAG"},
               {"root_log2_size", grid.active.dag.log2Size},
               {"root_origin", grid.active.dag.origin},
               {"levels", json::array()},
               {"sections", json::array()}};
        const auto& st = grid.stats;
        for (size_t i = 0; i < st.svoNodes.size(); ++i) {
            json level{{"node_size", uint64_t(1) << (i + 2)}, {"svo_nodes", st.svoNodes[i]}, {"stored_nodes", st.storedNodes[i]}};
            if (st.hasSvdag) level["svdag_nodes"] = st.svdagNodes[i];
            j["levels"].push_back(level);
        }
        uint64_t gridBytes = 0;
        for (const auto& s : sections) {
            if (s.kind == format::SectionKind::FileInfo || s.grid != g) continue;
            json section{{"kind", format::sectionKindName(s.kind)}, {"stored_bytes", s.storedBytes}, {"raw_bytes", s.rawBytes}, {"compressed", s.compressed}};
            // Predicted windows: how many windows each coding holds.
            if (s.kind == format::SectionKind::PredictedWindows || s.kind == format::SectionKind::InactivePredictedWindows) {
                const std::vector<uint64_t> counts = file.codings(uint32_t(g), s.kind == format::SectionKind::InactivePredictedWindows);
                if (!counts.empty()) {
                    json codings = json::object();
                    for (size_t c = 0; c < counts.size(); ++c) {
                        const char* name = attributes::predictedCodingName(uint8_t(c));  // two codings share a name
                        if (counts[c]) codings[name] = codings.value(name, uint64_t(0)) + counts[c];
                    }
                    section["window_codings"] = codings;
                }
            }
            j["sections"].push_back(section);
            gridBytes += s.storedBytes;
        }
        fileLevelBytes -= std::min(fileLevelBytes, gridBytes);
        j["stored_bytes"] = gridBytes;
        // Value channels: the columns of Dado et al.'s Table 1.
        j["channels"] = json::array();
        const unsigned vs = valueSize(grid.record.valueType);
        uint64_t traceable = grid.active.dag.byteSize() + grid.inactive.dag.byteSize();
        for (const auto& [layer, raw, inactive] : {std::tuple{"active", &grid.active.attributes, false},
                                                   std::tuple{"inactive", &grid.inactive.attributes, true}}) {
            if (!valueStats || !vs || raw->empty()) continue;
            const attributes::PaletteChannel channel = format::traceableValues(grid, inactive);
            const attributes::ChannelStats cs = attributes::channelStats(*raw, vs, channel);
            traceable += channel.byteSize();
            j["channels"].push_back({{"layer", layer}, {"entries", cs.entries}, {"unique", cs.unique}, {"raw_bytes", cs.rawBytes},
                                     {"material_index_bytes", cs.materialIndexBytes}, {"palette_bytes", cs.paletteBytes},
                                     {"palette_blocks", cs.paletteBlocks}, {"direct_blocks", cs.directBlocks}, {"palettes", cs.palettesStored}});
        }
        if (grid.normals) {
            traceable += grid.normals->codes.byteSize();
            j["normals"] = normalsJson(grid);
        }
        if (grid.colour) j["colour"] = colourJson(grid);
        if (valueStats) j["traceable_bytes"] = traceable;
        if (grid.lossy.tolerance.mode != attributes::ScalarTolerance::Mode::Exact)
            j["lossy"] = {{"tolerance", attributes::describe(grid.lossy.tolerance)}, {"changed", grid.lossy.changed},
                          {"max_abs_error", grid.lossy.maxAbsError}, {"mean_abs_error", grid.lossy.meanAbsError},
                          {"rms_error", grid.lossy.rmsError}, {"max_rel_error", grid.lossy.maxRelError}};
        if (const auto scan = bridge::scanProvenanceOf(grid.record)) {
            json sj{{"source_file", scan->sourceFile}, {"format", scan->format}, {"sample_type", scan->sampleType},
                    {"dims", {scan->dims[0], scan->dims[1], scan->dims[2]}}, {"space", scan->space}};
            if (scan->below) sj["background_below"] = *scan->below;
            if (scan->above) sj["background_above"] = *scan->above;
            if (scan->threshold) {
                const bridge::ThresholdReport& t = *scan->threshold;
                sj["threshold"] = {{"inactive_samples", t.inactive}, {"changed_samples", t.changed}, {"max_abs_change", t.maxAbsChange},
                                   {"rms_change", t.rmsChange}, {"psnr_db", std::isfinite(t.psnr) ? json(t.psnr) : json(nullptr)}, {"psnr_peak", "input range"}};
            }
            j["scan"] = sj;
        }
        report["grids"].push_back(j);
    }
    report["container_overhead_bytes"] = fileLevelBytes;
    // The one bits-per-voxel figure of a file, as `encode` prints it: the
    // whole file over every grid's active voxels.
    uint64_t voxels = 0;
    for (const format::EncodedGrid& grid : scene.grids) voxels += grid.active.voxels;
    report["active_voxels"] = voxels;
    report["bits_per_active_voxel"] = voxels ? 8.0 * double(file.bytes) / double(voxels) : 0.0;
    return report;
}

std::string formatSceneReport(const nlohmann::json& r) {
    const std::string format = r.value("format", "ssvdag");
    const bool vdb = format == "vdb" || format == "nvdb";
    std::string out = vdb ? fmt::format("{}: {} file{}, {} bytes, {} grid(s); encoded in memory as .ssvdag: {} bytes\n", r["input"].get<std::string>(),
                                        format == "vdb" ? "OpenVDB" : "NanoVDB",
                                        r.contains("vdb_file_version") ? fmt::format(" (format {})", r["vdb_file_version"].get<uint32_t>()) : std::string(),
                                        r["input_bytes"].get<uint64_t>(), r["grids"].size(), r["ssvdag_bytes"].get<uint64_t>())
                          : fmt::format("{}: .ssvdag file (format {}), {} bytes, {} grid(s)\n", r["input"].get<std::string>(),
                                        r.value("format_version", 0u), r["ssvdag_bytes"].get<uint64_t>(), r["grids"].size());
    if (r.contains("file_metadata"))
        for (const auto& [name, e] : r["file_metadata"].items()) out += fmt::format("file metadata {}: {}\n", name, e["value"].get<std::string>());
    for (const auto& g : r["grids"]) {
        const std::string root = g["root_log2_size"].get<int>() == 0
                                     ? std::string("empty")
                                     : fmt::format("root 2^{} at ({}, {}, {})", g["root_log2_size"].get<int>(), g["root_origin"][0].get<int64_t>(),
                                                   g["root_origin"][1].get<int64_t>(), g["root_origin"][2].get<int64_t>());
        out += fmt::format("grid {} '{}' ({}, {}): {} active voxels{}, {}, {}\n", g["index"].get<size_t>(), g["name"].get<std::string>(),
                           g["value_type"].get<std::string>(), g["class"].get<std::string>(), g["active_voxels"].get<uint64_t>(),
                           g.contains("active_tiles") ? fmt::format(" ({} active tiles)", g["active_tiles"].get<uint64_t>()) : std::string(),
                           g["encoding"].get<std::string>(), root);
        if (g.contains("tree_type")) out += formatGridHeader(g);
        if (!g["levels"].empty()) {
            out += fmt::format("  {:>10} {:>12} {:>12} {:>12}\n", "node size", "SVO nodes", "SVDAG nodes", g["encoding"].get<std::string>() + " nodes");
            for (size_t i = g["levels"].size(); i-- > 0;) {
                const auto& l = g["levels"][i];
                out += fmt::format("  {:>10} {:>12} {:>12} {:>12}\n", l["node_size"].get<uint64_t>(), l["svo_nodes"].get<uint64_t>(),
                                   l.contains("svdag_nodes") ? std::to_string(l["svdag_nodes"].get<uint64_t>()) : std::string("-"),
                                   l["stored_nodes"].get<uint64_t>());
            }
        }
        for (const auto& s : g["sections"]) {
            std::string codings;
            if (s.contains("window_codings"))
                for (const auto& [name, count] : s["window_codings"].items())
                    codings += fmt::format("{}{} {}", codings.empty() ? " (windows: " : ", ", count.get<uint64_t>(), name);
            if (!codings.empty()) codings += ")";
            out += fmt::format("  section {:<22} {:>12} bytes{}{}\n", s["kind"].get<std::string>(), s["stored_bytes"].get<uint64_t>(),
                               s["compressed"].get<bool>() ? fmt::format(" (zstd, {} raw)", s["raw_bytes"].get<uint64_t>()) : std::string(), codings);
        }
        for (const auto& c : g["channels"])
            out += fmt::format("  {} values: {} entries, {} unique; raw {} B, material+index {} B, palette-compressed {} B ({} palette / {} direct blocks, {} palettes)\n",
                               c["layer"].get<std::string>(), c["entries"].get<uint64_t>(), c["unique"].get<uint64_t>(), c["raw_bytes"].get<uint64_t>(),
                               c["material_index_bytes"].get<uint64_t>(), c["palette_bytes"].get<uint64_t>(), c["palette_blocks"].get<uint64_t>(),
                               c["direct_blocks"].get<uint64_t>(), c["palettes"].get<uint64_t>());
        if (g.contains("lossy"))
            out += fmt::format("  lossy values ({}): {} changed, max error {:.3g}, mean {:.3g}, RMS {:.3g}, max relative {:.3g}\n",
                               g["lossy"]["tolerance"].get<std::string>(), g["lossy"]["changed"].get<uint64_t>(), g["lossy"]["max_abs_error"].get<double>(),
                               g["lossy"]["mean_abs_error"].get<double>(), g["lossy"]["rms_error"].get<double>(), g["lossy"]["max_rel_error"].get<double>());
        if (g.contains("scan")) {
            const auto& sc = g["scan"];
            out += fmt::format("  scan: {} ({}, {} samples, {}x{}x{}{})\n", sc["source_file"].get<std::string>(), sc["format"].get<std::string>(),
                               sc["sample_type"].get<std::string>(), sc["dims"][0].get<int64_t>(), sc["dims"][1].get<int64_t>(), sc["dims"][2].get<int64_t>(),
                               sc["space"].get<std::string>().empty() ? std::string() : ", " + sc["space"].get<std::string>());
            if (sc.contains("threshold")) {
                const auto& t = sc["threshold"];
                std::string which;
                if (sc.contains("background_below")) which += fmt::format("below {:g}", sc["background_below"].get<double>());
                if (sc.contains("background_above")) which += fmt::format("{}above {:g}", which.empty() ? "" : " and ", sc["background_above"].get<double>());
                out += fmt::format("  threshold ({}): {} samples inactive, {} changed; max |change| {:.6g}, RMS {:.6g}; PSNR {} (peak = input range)\n", which,
                                   t["inactive_samples"].get<uint64_t>(), t["changed_samples"].get<uint64_t>(), t["max_abs_change"].get<double>(),
                                   t["rms_change"].get<double>(), t["psnr_db"].is_null() ? std::string("inf") : fmt::format("{:.2f} dB", t["psnr_db"].get<double>()));
            }
        }
        if (g.contains("colour")) out += "  " + formatColour(g["colour"]) + "\n";
        if (g.contains("normals")) out += "  " + formatNormals(g["normals"]) + "\n";
        out += fmt::format("  its sections: {} bytes in the {}{}\n", g["stored_bytes"].get<uint64_t>(), vdb ? ".ssvdag" : "file",
                           g.contains("traceable_bytes") ? fmt::format(", {} bytes traceable in memory", g["traceable_bytes"].get<uint64_t>())
                                                         : std::string(" (--values: value statistics and traceable size)"));
    }
    out += fmt::format("{} active voxels in {} bytes{}: {:.3f} bits/active voxel\n", r["active_voxels"].get<uint64_t>(), r["ssvdag_bytes"].get<uint64_t>(),
                       vdb ? " of .ssvdag" : "", r["bits_per_active_voxel"].get<double>());
    return out;
}

} // namespace vdbdag::app
