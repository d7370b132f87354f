// See EncodeFile.h. What `vdbdag encode` does with one input, from reading
// it to the report; cli/EncodeCommand.cpp parses and prints around it.
#include "app/EncodeFile.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>

#include <tbb/global_control.h>

#include <fmt/core.h>

#include "app/EncodeReportJson.h"
#include "app/MemoryBudget.h"
#include "src/attributes/ColourQuantizer.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "src/util/ParallelFor.h"
#include "src/util/Progress.h"
#include "vdb_bridge/NanoVdb.h"
#include "vdb_bridge/VdbCubes.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::app {

EncodeResult encodeFile(const EncodeRequest& request, const EncodeHooks& hooks) {
    pipeline::CubeTeam& team = hooks.team ? *hooks.team : pipeline::soloTeam();
    const auto start = std::chrono::steady_clock::now();
    std::optional<tbb::global_control> threads;
    if (request.threads) threads.emplace(tbb::global_control::max_allowed_parallelism, request.threads);
    bridge::ImportOptions importOptions;
    importOptions.onlyGrids = request.grids;
    importOptions.skipUnsupported = request.skipUnsupported;
    importOptions.topologyOnly = request.topologyOnly;
    importOptions.normals = request.normalBits != 0;
    importOptions.normalGrid = request.normalGrid;
    if (request.colourBits && request.topologyOnly) throw Error("--colour-bits and --topology-only exclude each other: a topology-only file has no colours");
    const bool dense = bridge::denseFormatOf(request.input) != bridge::DenseFormat::None;
    checkOutputPath(request.output, request.inputFiles.empty() ? std::vector<std::string>{request.input} : request.inputFiles, {{".ssvdag"}, "encode", request.force});
    // Scratch files are named after the output, in its folder or in --scratch.
    const std::string scratchNear = request.scratch.empty() ? request.output : (std::filesystem::path(request.scratch) / std::filesystem::path(request.output).filename()).string();
    bridge::ImportResult imported;
    std::optional<bridge::VdbCubeInput> cubeInput;  // --memory-limit on a .vdb: read region by region
    std::vector<std::unique_ptr<CubeSource>> denseCubes;  // ... on a scalar scan: its samples in a scratch file
    bridge::ThresholdReport threshold;
    if (dense) {
        if (!request.grids.empty()) throw Error(request.input + ": --grid applies to .vdb inputs only (a dense scan has one grid)");
        if (request.normalBits)
            throw Error(request.input + ": --normals applies to the level sets and vec3 normal grids of a .vdb or .nvdb, not to a dense scan");
        bridge::DenseImportOptions denseOptions = request.dense;
        // Cube by cube, its samples in a scratch file, with
        // --memory-limit, under mpirun, or when the grid would not fit
        // in memory (about 12 bytes per sample in all, against the
        // default limit); the same bytes either way.
        if (!request.topologyOnly) {
            if (request.memoryLimit || team.size() > 1 || bridge::describeDense(request.input, denseOptions).sampleCount() > defaultMemoryLimit() / 12)
                denseOptions.cubesNear = scratchNear;
        }
        bridge::DenseImportResult dense = bridge::importDense(request.input, denseOptions);
        threshold = dense.threshold;
        imported.warnings = dense.source.notes;
        imported.volume = std::move(dense.volume);
        denseCubes = std::move(dense.cubes);
        if (request.topologyOnly)
            for (GridRecord& g : imported.volume.grids) {
                g.valueType = ValueType::Mask;
                g.values = {};
                g.background.clear();
            }
    } else {
        // Cube by cube (region by region from the file) whenever the
        // file allows it (grid offsets): less memory than the whole grid
        // and faster too (the cubes' values are gathered in parallel,
        // each through a small index); --normals from each cube with
        // a one-voxel halo. Whole, through OpenVDB's strictest reader,
        // for a stream, and for --normals of a topology-only encode (the
        // gradient needs the values). The same bytes either way.
        if (bridge::isNanoVdbPath(request.input)) {  // NanoVDB: whole, through NanoVDB's own converter
            imported = bridge::importNanoVdb(request.input, importOptions);
        } else if (!(importOptions.normals && importOptions.topologyOnly) && bridge::canReadVdbByCubes(request.input)) {
            cubeInput = bridge::openVdbCubes(request.input, importOptions, scratchNear,
                                             scratchInMemory(request.memoryLimit ? request.memoryLimit : defaultMemoryLimit()));
            imported.warnings = cubeInput->warnings;
            for (const auto& g : cubeInput->grids) imported.volume.grids.push_back(g->header());  // headers only, for the checks
        } else {
            imported = bridge::importVdb(request.input, importOptions);
        }
    }
    if (hooks.warning)
        for (const auto& w : imported.warnings) hooks.warning(w);
    if (imported.volume.grids.empty())
        throw Error(request.input + ": " + (imported.warnings.empty() ? "has no grids" : "has no grid vdbdag converts") + "; nothing to write to " + request.output);
    for (const std::string& name : request.colourGrids) {
        const auto& grids = imported.volume.grids;
        const auto it = std::find_if(grids.begin(), grids.end(), [&](const GridRecord& g) { return g.name == name; });
        if (it == grids.end()) throw Error(request.input + ": no grid named '" + name + "' among the grids encoded, for --colour-grid");
        if (!attributes::isVec3Type(it->valueType))
            throw Error(request.input + ": --colour-grid '" + name + "' holds " + valueTypeName(it->valueType) + " values, not vec3 colours");
    }

    pipeline::EncodeOptions encodeOptions;
    encodeOptions.symmetry = !request.noSymmetry;
    encodeOptions.placementTrials = request.placementTrials;
    encodeOptions.predictIntegers = !request.noPredict;
    encodeOptions.computeSvdagStats = request.svdagStats;
    if (request.absError > 0) encodeOptions.tolerance = {attributes::ScalarTolerance::Mode::Absolute, request.absError};
    if (request.relError > 0) encodeOptions.tolerance = {attributes::ScalarTolerance::Mode::Relative, request.relError};
    encodeOptions.colourBits = request.colourBits;
    encodeOptions.colourGrids = request.colourGrids;
    encodeOptions.normalBits = request.normalBits;
    encodeOptions.keepAttributes = false;  // the file is written, the attribute arrays dropped (below)
    // Each step is 1000 units, filled cube by cube where the encoder reports it.
    constexpr uint64_t kUnits = 1000;
    const uint64_t totalUnits = (imported.volume.grids.size() * pipeline::kEncodeSteps + 1) * kUnits;
    Progress progress("encode", totalUnits);
    const auto setProgress = [&](uint64_t units) {
        progress.set(units);
        if (hooks.onProgress) hooks.onProgress(double(std::min(units, totalUnits)) / double(totalUnits));
    };
    std::string gridName;
    uint64_t stepsStarted = 0;
    // Seconds spent in each step, reported with --json ("phases").
    std::vector<std::pair<std::string, std::chrono::steady_clock::time_point>> phases{{"reading the input", start}};
    encodeOptions.onStep = [&](const char* step) {
        phases.push_back({fmt::format("{}: {}", gridName, step), std::chrono::steady_clock::now()});
        progress.setLabel(fmt::format("encode '{}': {}", gridName, step));
        setProgress(stepsStarted++ * kUnits);
    };
    encodeOptions.onStepProgress = [&](uint64_t done, uint64_t total) {
        if (stepsStarted && total) setProgress((stepsStarted - 1) * kUnits + std::min<uint64_t>(kUnits, done * kUnits / total));
    };
    std::vector<std::string> gridNames;
    for (const auto& g : imported.volume.grids) gridNames.push_back(g.name);

    format::SsvdagScene scene;
    const auto onGrid = [&](size_t i, size_t) { gridName = gridNames[i]; };
    pipeline::SeriesReferenceReport series;
    try {
        // A grid read whole (a small scan, an OpenVDB stream) is encoded
        // in memory, which costs least (the same bytes), except under
        // mpirun, where the processes share its cubes.
        if (cubeInput || !denseCubes.empty() || team.size() > 1) {
            const pipeline::CubeBudget budget = cubeBudget(request.memoryLimit, scratchNear);
            std::vector<std::unique_ptr<CubeSource>> sources;
            if (!denseCubes.empty()) {
                sources = std::move(denseCubes);
            } else if (cubeInput) {
                sources = std::move(cubeInput->grids);
                imported.volume.fileMetadata = cubeInput->fileMetadata;
            } else {
                for (const GridRecord& g : imported.volume.grids) sources.push_back(recordCubes(g));
            }
            scene = pipeline::encodeSourcesByCubes(std::move(sources), imported.volume.fileMetadata, encodeOptions, budget, onGrid, team);
        } else {
            scene = pipeline::encodeVolumeReleasing(imported.volume, encodeOptions, onGrid);
        }
        // A 4-D scan's volumes, each with the one before as its reference
        // where that is smaller (lossless only: the pass takes exact grids
        // alone), keeping decoded windows within a quarter of the memory limit.
        if (dense && scene.grids.size() > 1 && request.keyEvery > 1 && team.isRoot()) {
            phases.push_back({"coding the volumes against the one before", std::chrono::steady_clock::now()});
            progress.setLabel("encode: coding the volumes against the one before");
            series = pipeline::referenceSeries(scene, request.keyEvery, (request.memoryLimit ? request.memoryLimit : defaultMemoryLimit()) / 4);
        }
    } catch (const Error& e) {
        throw Error(request.input + ": " + e.what());  // e.g. a colour grid holding NaN: name the file too
    }
    // Neither the input voxels nor the attribute arrays are written:
    // release them before the sections are built (a 512x512x999 scan
    // holds 1 GB in each).
    imported.volume = {};
    for (auto& g : scene.grids) {
        std::vector<uint8_t>().swap(g.active.attributes);
        std::vector<uint8_t>().swap(g.inactive.attributes);
    }
    EncodeResult result;
    if (!team.isRoot()) return result;  // process 0 writes and reports
    phases.push_back({"writing the file", std::chrono::steady_clock::now()});
    progress.setLabel("encode: writing " + request.output);
    format::ContainerOptions containerOptions;
    containerOptions.compress = !request.noCompress;
    containerOptions.parallel = util::tbbParallelFor();  // the sections compressed side by side
    // Section by section, the DAGs and values released as they go: the
    // file is never whole in memory.
    uint64_t fileBytes = 0, geometryBytes = 0;  // the DAGs, uncompressed (released by the writer)
    for (const auto& g : scene.grids) geometryBytes += g.active.dag.byteSize() + g.inactive.dag.byteSize();
    writeStreamAtomically(request.output, [&](std::ostream& out) { fileBytes = format::writeSceneReleasing(scene, out, containerOptions); });
    progress.finish();
    // Where the geometry weighs, other root placements may shrink it
    // (a tilted torus: 30%): say that the option exists.
    if (hooks.note && request.placementTrials == 1 && fileBytes && geometryBytes * 4 > fileBytes)
        hooks.note("the geometry is a large part of this file: --placement-trials 4 tries other root placements and keeps the smallest file");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    uint64_t voxels = 0;
    for (const auto& g : scene.grids) voxels += g.active.voxels;
    nlohmann::json grids = nlohmann::json::array();
    for (size_t g = 0; g < scene.grids.size(); ++g)
        grids.push_back({{"index", g}, {"name", scene.grids[g].record.name}, {"class", scene.grids[g].record.gridClass},
                         {"value_type", valueTypeName(scene.grids[g].record.valueType)}, {"active_voxels", scene.grids[g].active.voxels}});
    // "bytes": the file written, as "ssvdag_bytes" (kept for scripts written before the common keys).
    nlohmann::json report{{"input", request.input}, {"output", request.output}, {"ssvdag_bytes", fileBytes}, {"bytes", fileBytes},
                          {"grid_count", scene.grids.size()}, {"grids", grids}, {"active_voxels", voxels}, {"seconds", seconds},
                          {"bits_per_active_voxel", voxels ? 8.0 * double(fileBytes) / double(voxels) : 0.0}};
    if (threshold.applied) report["threshold"] = thresholdJson(threshold);
    if (series.referencedGrids)
        report["series_reference"] = {{"key_every", request.keyEvery}, {"referenced_grids", series.referencedGrids},
                                      {"referenced_windows", series.referencedWindows}, {"window_bytes_before", series.bytesBefore},
                                      {"window_bytes_after", series.bytesAfter}};
    report["phases"] = nlohmann::json::array();
    for (size_t i = 0; i < phases.size(); ++i) {
        const auto end = i + 1 < phases.size() ? phases[i + 1].second : start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
        report["phases"].push_back({{"name", phases[i].first}, {"seconds", std::chrono::duration<double>(end - phases[i].second).count()}});
    }
    report["grids_lossy"] = nlohmann::json::array();
    for (const auto& g : scene.grids) {
        if (g.lossy.tolerance.mode == attributes::ScalarTolerance::Mode::Exact) continue;
        report["grids_lossy"].push_back({{"name", g.record.name}, {"tolerance", attributes::describe(g.lossy.tolerance)},
                                         {"entries", g.lossy.entries}, {"changed", g.lossy.changed}, {"kept_exact", g.lossy.keptExact},
                                         {"max_abs_error", g.lossy.maxAbsError}, {"mean_abs_error", g.lossy.meanAbsError},
                                         {"rms_error", g.lossy.rmsError}, {"max_rel_error", g.lossy.maxRelError}});
    }
    report["grids_colour"] = nlohmann::json::array();
    report["grids_normals"] = nlohmann::json::array();
    for (const auto& g : scene.grids) {
        if (g.colour) report["grids_colour"].push_back(colourJson(g));
        if (g.normals) report["grids_normals"].push_back(normalsJson(g));
    }
    result.written = true;
    result.report = std::move(report);
    result.threshold = threshold;
    return result;
}

} // namespace vdbdag::app
