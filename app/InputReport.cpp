// See InputReport.h.
#include "app/InputReport.h"

#include <cmath>
#include <filesystem>
#include <tuple>

#include <fmt/core.h>

#include "app/ReportVersions.h"
#include "app/SceneReport.h"
#include "src/attributes/PredictedWindows.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "src/util/ParallelFor.h"
#include "vdb_bridge/DenseImport.h"
#include "vdb_bridge/DicomSeries.h"
#include "vdb_bridge/InputScene.h"
#include "vdb_bridge/NanoVdb.h"
#include "vdb_bridge/NiftiHeader.h"
#include "vdb_bridge/VdbImport.h"
#include "vdb_bridge/VdbSummary.h"

namespace vdbdag::app {
namespace {

// `info --values` reads every value: the Summary sections (docs/FORMAT.md
// 10.1) are checked against what the grids' DAGs and values give, as
// NanoVDB's validator recomputes its grid's bounding boxes. A Summary that
// says otherwise is refused naming the file (it would mislead `info` and
// the reader library).
void checkSummaries(const format::SsvdagScene& scene, const std::string& input) {
    for (size_t g = 0; g < scene.grids.size(); ++g) {
        const format::EncodedGrid& grid = scene.grids[g];
        if (!grid.summary) continue;
        const format::StoredSummary want = format::recomputedSummary(grid);
        const format::StoredSummary& have = *grid.summary;
        const auto box = [](const std::optional<format::IndexBox>& b) {
            return b ? fmt::format("[{}, {}, {}] -> [{}, {}, {}]", b->min[0], b->min[1], b->min[2], b->max[0], b->max[1], b->max[2]) : std::string("none");
        };
        const ValueType type = grid.record.valueType;
        const auto range = [&](const attributes::ValueRange& r) {
            return r.empty() ? std::string("none") : format::formatValue(type, r.min) + " to " + format::formatValue(type, r.max);
        };
        std::string why;
        if (box(have.indexBox) != box(want.indexBox)) why = "an index box " + box(have.indexBox) + ", its DAG " + box(want.indexBox);
        else if (have.solidNodes != want.solidNodes) why = fmt::format("{} solid nodes, its DAG {}", have.solidNodes, want.solidNodes);
        else if (have.activeEntries != want.activeEntries || have.inactiveEntries != want.inactiveEntries)
            why = fmt::format("{} and {} entries, its DAGs {} and {}", have.activeEntries, have.inactiveEntries, want.activeEntries, want.inactiveEntries);
        else if (have.activeRange.min != want.activeRange.min || have.activeRange.max != want.activeRange.max)
            why = "active values from " + range(have.activeRange) + ", its values " + range(want.activeRange);
        if (!why.empty()) throw Error(fmt::format("{}: grid {} '{}': its Summary section says {}; the file is corrupted", input, g, grid.record.name, why));
    }
}

// `info` of an .ssvdag file reads what it prints: where every grid has a
// Summary section (docs/FORMAT.md 10.1), the section table, the grids'
// headers, DagLevels and statistics, and of each PredictedWindows section
// its directory and each window's first byte; the DAGs and the values stay
// in the file. A file without (written before Summary sections) or with
// normals, whose report needs their channel, gets nullopt: it is read whole.
std::optional<std::pair<format::SsvdagScene, nlohmann::json>> reportFromHeaders(const InfoRequest& opt, const std::string& input) {
    using format::SectionKind;
    const std::vector<format::Section> stored = format::storedSectionsOf(input);
    for (const format::Section& s : stored)
        if (s.kind == SectionKind::Normals) return std::nullopt;
    format::ReadOptions readOptions;
    readOptions.limits = opt.limits;
    readOptions.headersOnly = true;
    format::SsvdagScene scene = format::readSceneFile(input, readOptions);
    for (const format::EncodedGrid& grid : scene.grids)
        if (!grid.summary) return std::nullopt;
    StoredScene file;
    file.bytes = std::filesystem::file_size(input);
    for (const format::Section& s : stored) file.sections.push_back({s.kind, s.grid, s.stored->zstd, s.stored->storedBytes, s.stored->rawBytes});
    file.codings = [&](uint32_t g, bool inactive) -> std::vector<uint64_t> {
        const SectionKind kind = inactive ? SectionKind::InactivePredictedWindows : SectionKind::PredictedWindows;
        const std::string what = input + ": grid " + std::to_string(g) + (inactive ? " inactive" : "") + " predicted windows";
        const unsigned vs = valueSize(scene.grids[g].record.valueType);
        for (const format::Section& s : stored) {
            if (s.kind != kind || s.grid != g) continue;
            if (s.stored->zstd) {  // another writer's: the section whole
                const auto whole = format::readContainerFile(input, false, opt.limits, [&](SectionKind k, uint32_t grid) { return k == kind && grid == g; });
                return attributes::predictedWindowCodings(
                    whole.at(0).data.size(), [&](uint64_t at, uint64_t n) { return std::vector<uint8_t>(whole[0].data.begin() + long(at), whole[0].data.begin() + long(at + n)); }, vs, what);
            }
            const format::StoredPayloadReader reader(*s.stored);
            return attributes::predictedWindowCodings(reader.size(), [&](uint64_t at, uint64_t n) { return reader.read(at, n); }, vs, what);
        }
        return {};
    };
    nlohmann::json report = sceneReport(scene, file, input, false);
    return std::make_pair(std::move(scene), std::move(report));
}

nlohmann::json dicomReport(const std::string& input, const bridge::DicomScan& scan) {
    nlohmann::json series = nlohmann::json::array();
    for (size_t i = 0; i < scan.series.size(); ++i) {
        const bridge::DicomSeriesInfo& s = scan.series[i];
        series.push_back({{"index", i + 1}, {"uid", s.uid}, {"modality", s.modality}, {"description", s.description},
                          {"series_number", s.seriesNumber}, {"slices", s.dims[2]}, {"missing_slices", s.missingSlices}, {"dims", {s.dims[0], s.dims[1], s.dims[2]}},
                          {"spacing", {s.spacing[0], s.spacing[1], s.spacing[2]}}, {"sample_type", s.sampleType},
                          {"convertible", s.problem.empty()}, {"problem", s.problem}, {"notes", s.notes}});
    }
    return {{"input", input}, {"format", "dicom"}, {"series", series}, {"skipped_files", scan.skipped.size()}, {"skipped", scan.skipped}};
}

std::string formatDicomReport(const nlohmann::json& r) {
    std::string out = fmt::format("{}: DICOM, {} series, {} file(s) skipped\n", r["input"].get<std::string>(), r["series"].size(),
                                  r["skipped_files"].get<size_t>());
    for (const auto& s : r["series"]) {
        const auto& d = s["dims"];
        const auto& sp = s["spacing"];
        out += fmt::format("  {}) {}  {}  \"{}\"  {} slices  {}x{}x{} {}  spacing {:.6g} x {:.6g} x {:.6g} mm\n", s["index"].get<size_t>(),
                           s["uid"].get<std::string>(), s["modality"].get<std::string>(), s["description"].get<std::string>(),
                           s["slices"].get<int64_t>(), d[0].get<int64_t>(), d[1].get<int64_t>(), d[2].get<int64_t>(),
                           s["sample_type"].get<std::string>().empty() ? "?" : s["sample_type"].get<std::string>(), sp[0].get<double>(),
                           sp[1].get<double>(), sp[2].get<double>());
        for (const auto& n : s["notes"]) out += fmt::format("       note: {}\n", n.get<std::string>());
        if (!s["convertible"].get<bool>()) out += fmt::format("       not convertible: {}\n", s["problem"].get<std::string>());
    }
    const auto& skipped = r["skipped"];
    constexpr size_t kShown = 10;
    for (size_t i = 0; i < skipped.size() && i < kShown; ++i) out += fmt::format("  skipped {}\n", skipped[i].get<std::string>());
    if (skipped.size() > kShown) out += fmt::format("  ... and {} more skipped (--json lists all)\n", skipped.size() - kShown);
    return out;
}
// A scan's header as vdbdag reads it (NRRD, MetaImage, NIfTI; .raw from
// its name): what `encode` would make of it.
nlohmann::json scanHeaderReport(const std::string& input, const bridge::DenseVolume& v) {
    nlohmann::json axes = nlohmann::json::array();
    nlohmann::json spacing = nlohmann::json::array();
    for (const auto& a : v.axes) {
        axes.push_back({a[0], a[1], a[2]});
        spacing.push_back(std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]));
    }
    nlohmann::json r{{"input", input},
                     {"format", bridge::denseFormatName(v.format)},
                     {"dims", {v.dims[0], v.dims[1], v.dims[2]}},
                     {"sample_type", bridge::sampleTypeName(v.type)},
                     {"components", v.components},
                     {"colour", v.colour},
                     {"space", v.space},
                     {"origin", {v.origin[0], v.origin[1], v.origin[2]}},
                     {"axes", axes},
                     {"spacing", spacing},
                     {"rescale_slope", v.rescaleSlope},
                     {"rescale_intercept", v.rescaleIntercept},
                     {"data_file", v.dataPath},
                     {"compressed", v.encoding == bridge::DataEncoding::Zlib}};
    if (v.format == bridge::DenseFormat::Nifti || v.format == bridge::DenseFormat::Nrrd) r["volumes"] = bridge::volumeCountOf(input);
    return r;
}

std::string formatScanHeaderReport(const nlohmann::json& r) {
    const auto& d = r["dims"];
    const auto& sp = r["spacing"];
    std::string out = fmt::format("{}: {} scan, {}x{}x{} {}{} samples{}, spacing {:.6g} x {:.6g} x {:.6g}{}\n", r["input"].get<std::string>(),
                                  r["format"].get<std::string>(), d[0].get<int64_t>(), d[1].get<int64_t>(), d[2].get<int64_t>(),
                                  r["sample_type"].get<std::string>(), r["components"].get<unsigned>() > 1 ? fmt::format(" x{}", r["components"].get<unsigned>()) : "",
                                  r["colour"].get<bool>() ? " (RGB)" : "", sp[0].get<double>(), sp[1].get<double>(), sp[2].get<double>(),
                                  r["space"].get<std::string>().empty() ? "" : " (" + r["space"].get<std::string>() + ")");
    const auto& o = r["origin"];
    out += fmt::format("  origin ({:.6g}, {:.6g}, {:.6g}); data {}{}\n", o[0].get<double>(), o[1].get<double>(), o[2].get<double>(),
                       r["data_file"].get<std::string>(), r["compressed"].get<bool>() ? " (gzip)" : "");
    if (r["rescale_slope"].get<double>() != 1 || r["rescale_intercept"].get<double>() != 0)
        out += fmt::format("  rescale: value = stored x {:.17g} + {:.17g}\n", r["rescale_slope"].get<double>(), r["rescale_intercept"].get<double>());
    if (r.contains("volumes") && r["volumes"].get<int64_t>() > 1)
        out += fmt::format("  {} volumes: encode makes one grid per volume, or pick one with --volume N\n", r["volumes"].get<int64_t>());
    return out;
}

// A volume read from a .vdb or .nvdb as `encode` would write it (with the
// plain SVDAG's counts `info` shows), in memory: the scene and its report.
std::pair<format::SsvdagScene, nlohmann::json> encodedReport(const InfoRequest& opt, const Volume& volume, const std::string& input) {
    pipeline::EncodeOptions options;
    options.symmetry = !opt.noSymmetry;
    options.computeSvdagStats = true;
    format::SsvdagScene scene = pipeline::encodeVolume(volume, options);
    nlohmann::json report = sceneReport(scene, format::writeScene(scene), input, true);
    return {std::move(scene), std::move(report)};
}

} // namespace

// One input's report and its text (a scan's header, a .nvdb, an .ssvdag or a .vdb).
std::pair<nlohmann::json, std::string> describeInput(const InfoRequest& opt, const std::string& input) {
    if (const bridge::DenseFormat f = bridge::denseFormatOf(input); f != bridge::DenseFormat::None) {
        // A .raw file by the layout its name gives (describeRaw says what is missing).
        // describeDense describes a 4-D NIfTI file by its first volume.
        nlohmann::json report = scanHeaderReport(input, bridge::describeDense(input, bridge::DenseImportOptions{}));
        return {report, formatScanHeaderReport(report)};
    }
    nlohmann::json report;
    // By magic number (bridge::inputKindOf; only a regular file is opened to
    // look: a FIFO or a device goes on to readFileBytes, which refuses it).
    const bridge::InputKind kind = bridge::inputKindOf(input);
    std::optional<uint32_t> fileVersion;  // an .ssvdag input's container version
    if (kind == bridge::InputKind::NanoVdb) {
        // NanoVDB: read through NanoVDB's converter as `encode` reads it,
        // then the DAG figures of its encoding in memory.
        format::SsvdagScene scene;
        std::tie(scene, report) = encodedReport(opt, bridge::importNanoVdb(input).volume, input);
        report["format"] = "nvdb";
        report["input_bytes"] = std::filesystem::file_size(input);
        for (size_t g = 0; g < scene.grids.size(); ++g) {
            const format::GridSummary summary = format::summarizeGrid(scene.grids[g]);
            const std::string what = input + " grid " + std::to_string(g);
            addGridHeader(report["grids"][g], scene.grids[g].record, bridge::gridHeaderFacts(scene.grids[g].record, summary.indexBox, what), summary,
                          false);
        }
    } else if (kind != bridge::InputKind::Vdb) {
        std::optional<std::pair<format::SsvdagScene, nlohmann::json>> headers = opt.values ? std::nullopt : reportFromHeaders(opt, input);
        format::SsvdagScene scene;
        if (headers) {
            scene = std::move(headers->first);
            report = std::move(headers->second);
        } else {
            const std::vector<uint8_t> bytes = format::readFileBytes(input);
            // Nothing decoded but what is printed: value windows stay as
            // they are in the file (their range is read window by window)
            // unless --values asks for the channels' statistics.
            format::ReadOptions readOptions;
            readOptions.parallel = util::tbbParallelFor();  // predicted windows on every core
            readOptions.limits = opt.limits;
            readOptions.keepValueWindows = !opt.values;
            scene = format::readScene(bytes, input, readOptions);
            if (opt.values) checkSummaries(scene, input);
            report = sceneReport(scene, bytes, input, opt.values);
        }
        report["format"] = "ssvdag";
        report["input_bytes"] = report["ssvdag_bytes"];
        // The file's container version: 3 where a grid's values take an
        // earlier grid's as their reference, 2 where a grid's inside is a
        // signed fill (docs/FORMAT.md 3.1).
        fileVersion = std::any_of(scene.grids.begin(), scene.grids.end(), [](const format::EncodedGrid& g) { return g.active.valueWindows.referenceDistance != 0; })
                          ? 3u
                      : std::any_of(scene.grids.begin(), scene.grids.end(), [](const format::EncodedGrid& g) { return g.inactiveSignedFill; })
                          ? 2u
                          : format::kFormatVersion;
        for (size_t g = 0; g < scene.grids.size(); ++g) {
            const format::EncodedGrid& grid = scene.grids[g];
            const std::string what = input + " grid " + std::to_string(g);
            const format::GridSummary summary = format::summarizeGrid(grid);
            addGridHeader(report["grids"][g], grid.record, bridge::gridHeaderFacts(grid.record, summary.indexBox, what), summary, false);
        }
        report["file_metadata"] = metadataJson(bridge::fileMetadataEntries(scene.fileMetadata, input + " file metadata"));
        if (!scene.frames.empty()) {  // a sequence: each frame's grids and its .vdb file's metadata
            report["frames"] = nlohmann::json::array();
            for (const format::SceneFrame& f : scene.frames) {
                report["frames"].push_back({{"frame", f.number}, {"first_grid", f.firstGrid}, {"grid_count", f.gridCount},
                                            {"file_metadata", metadataJson(bridge::fileMetadataEntries(f.metadata, input + " frame " + std::to_string(f.number) + " metadata"))}});
                for (uint32_t g = f.firstGrid; g < f.firstGrid + f.gridCount; ++g) report["grids"][g]["frame"] = f.number;
            }
        }
    } else {
        // OpenVDB's own figures (the reference vdb_print shows), then the
        // DAG figures of its encoding in memory.
        const uint64_t fileBytes = std::filesystem::file_size(input);  // never read whole here: OpenVDB reads it
        const bridge::VdbFileFacts facts = bridge::vdbFileFacts(input);
        format::SsvdagScene scene;
        std::tie(scene, report) = encodedReport(opt, bridge::importVdb(input).volume, input);
        report["format"] = "vdb";
        report["input_bytes"] = fileBytes;
        report["vdb_file_version"] = facts.fileVersion;
        if (facts.grids.size() != scene.grids.size()) throw Error(input + ": internal error: grids read twice differ in number");
        for (size_t g = 0; g < facts.grids.size(); ++g) {
            const bridge::VdbGridFacts& f = facts.grids[g];
            GridRecord header = f.header;
            header.background = scene.grids[g].record.background;
            addGridHeader(report["grids"][g], header, f.facts, f.summary, true);
        }
        report["file_metadata"] = metadataJson(facts.fileMetadata);
    }
    addVersions(report);  // the text names the format version too
    if (fileVersion) report["format_version"] = *fileVersion;  // an .ssvdag's own
    std::string text = formatSceneReport(report);
    if (report.contains("frames")) {  // after the file's line: the frames and their grids
        const auto& frames = report["frames"];
        std::string lines = fmt::format("{} frames, {} to {}:\n", frames.size(), frames.front()["frame"].get<int64_t>(), frames.back()["frame"].get<int64_t>());
        for (const auto& f : frames) {
            const auto first = f["first_grid"].get<uint64_t>(), count = f["grid_count"].get<uint64_t>();
            lines += fmt::format("  frame {}: grid{} {}\n", f["frame"].get<int64_t>(), count > 1 ? "s" : "",
                                 count > 1 ? fmt::format("{} to {}", first, first + count - 1) : std::to_string(first));
        }
        const size_t eol = text.find('\n');
        text.insert(eol == std::string::npos ? text.size() : eol + 1, lines);
    }
    return {report, text};
}

std::pair<nlohmann::json, std::string> describeDicom(const std::vector<std::string>& inputs) {
    // Descriptions may be Latin-1 (Specific Character Set): never throw on them.
    nlohmann::json report = dicomReport(bridge::dicomInputName(inputs), bridge::scanDicom(inputs));
    std::string text = formatDicomReport(report);
    return {std::move(report), std::move(text)};
}

} // namespace vdbdag::app
