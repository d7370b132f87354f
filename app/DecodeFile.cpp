// See DecodeFile.h. What `vdbdag decode` does with one file (or one frame
// of a sequence); cli/DecodeCommand.cpp parses and prints around it.
#include "app/DecodeFile.h"

#include <algorithm>
#include <chrono>
#include <filesystem>

#include "app/FrameJobs.h"
#include "src/format/FrameSequence.h"
#include "src/pipeline/GridCodec.h"
#include "src/pipeline/LayerScatter.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "src/util/ParallelFor.h"
#include "src/util/Progress.h"
#include "vdb_bridge/DenseExport.h"
#include "vdb_bridge/NanoVdb.h"
#include "vdb_bridge/VdbExport.h"

namespace vdbdag::app {
namespace {

// The grid a dense output takes: the one named, or the file's only grid.
template <typename Grid, typename NameOf>
const Grid& denseGridOf(const std::vector<Grid>& grids, const std::string& input, const std::string& name, NameOf nameOf) {
    if (!name.empty()) {
        for (const Grid& g : grids)
            if (nameOf(g) == name) return g;
        throw Error(input + ": has no grid named '" + name + "'");
    }
    if (grids.size() != 1) {
        std::string names;
        for (const Grid& g : grids) names += (names.empty() ? "'" : ", '") + nameOf(g) + "'";
        throw Error(input + ": holds " + std::to_string(grids.size()) + " grids (" + names + "); a scan file holds one: pick it with --grid NAME");
    }
    return grids.front();
}

// A dense output straight from the DAG, cube by cube, the values decoded a
// window at a time: never the whole grid in memory. False when the output
// or the grid needs the whole grid (exportsByCubes).
bool decodeDenseByCubes(const format::SsvdagScene& scene, const std::string& input, const std::string& output, const std::string& gridName,
                        const bridge::DenseExportOptions& options, std::vector<std::string>& notes) {
    if (gridName.empty() && scene.grids.size() > 1) {
        // The volumes of a 4-D scan are written from the decoded grids; any
        // other file of several grids is refused now, before it is decoded.
        std::vector<GridRecord> headers;
        for (const auto& g : scene.grids) headers.push_back(g.record);
        if (!bridge::volumeSeriesOf(headers)) denseGridOf(scene.grids, input, gridName, [](const format::EncodedGrid& g) { return g.record.name; });
        return false;
    }
    const format::EncodedGrid& grid = denseGridOf(scene.grids, input, gridName, [](const format::EncodedGrid& g) { return g.record.name; });
    if (!bridge::exportsByCubes(grid.record, output)) return false;
    constexpr unsigned kCubeLog2 = 7;
    const uint64_t total = (grid.inactive.dag.empty() ? 0 : 1) + (grid.active.dag.empty() ? 0 : 1);
    Progress progress("decode " + std::filesystem::path(output).filename().string(), 1000 * std::max<uint64_t>(total, 1));
    const bridge::DenseExportReport report = bridge::exportDenseByCubes(grid.record, output, [&](bridge::DenseCubeSink& sink) {
        uint64_t layer = 0;
        for (const bool inactive : {true, false}) {  // inactive first: active voxels win
            if (grid.layer(inactive).dag.empty()) continue;
            pipeline::LayerCubes visit;
            visit.begin = [&](const encoding::SubtreeInstance& s) { sink.beginCube(s.x, s.y, s.z, s.solid ? 2 : s.log2Size); };
            visit.voxels.brick = [&](int64_t x, int64_t y, int64_t z, uint64_t mask, const uint8_t* values) { sink.brick(x, y, z, mask, values); };
            visit.voxels.solid = [&](int64_t x, int64_t y, int64_t z, unsigned log2, const uint8_t* value) { sink.solid(x, y, z, log2, value); };
            visit.end = [&] { sink.endCube(); };
            pipeline::scatterLayerByCubes(grid, inactive, kCubeLog2, visit,
                                          [&](uint64_t done, uint64_t all) { progress.set(layer * 1000 + done * 1000 / std::max<uint64_t>(all, 1)); });
            ++layer;
        }
    }, options);
    progress.finish();
    notes = report.notes;
    return true;
}

} // namespace

DecodeResult decodeFile(const DecodeRequest& request) {
    const std::string& output = request.output;
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::string> notes;
    size_t gridCount = 0;
    uint64_t activeVoxels = 0;
    // The report once the output is in place.
    auto result = [&] {
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::error_code ec;
        const uint64_t bytes = std::filesystem::file_size(output, ec);
        DecodeResult r;
        r.report = {{"input", request.input}, {"output", output}, {"grids", gridCount}, {"active_voxels", activeVoxels},
                    {"output_bytes", ec ? 0 : bytes}, {"seconds", seconds}, {"notes", notes}};
        r.notes = notes;
        return r;
    };
    const bool dense = bridge::isDenseOutput(output);
    const bool nano = lowerExtension(output) == ".nvdb";
    if (!dense && !nano && lowerExtension(output) != ".vdb")
        throw Error(output + ": decode writes .vdb or .nvdb, or a dense scan as .nrrd, .nhdr, .mha, .mhd, .nii, .nii.gz or .raw");
    if (!dense && !request.grid.empty()) throw Error(output + ": --grid applies to scan outputs (a .vdb or .nvdb file takes every grid)");
    if (!dense && request.storedValues) throw Error(output + ": --stored-values applies to scan outputs (a .vdb or .nvdb file holds the grid's values)");
    bridge::DenseExportOptions denseOptions;
    denseOptions.storedValues = request.storedValues;
    const OutputRules rules{{".vdb", ".nvdb", ".nrrd", ".nhdr", ".mha", ".mhd", ".nii", ".gz", ".raw"}, "decode", request.force};
    checkOutputPath(output, {request.input}, rules);
    const std::string ext = lowerExtension(output);
    if (ext == ".nhdr" || ext == ".mhd")  // their samples go beside them, as NAME.raw
        checkOutputPath((std::filesystem::path(output).parent_path() / (std::filesystem::path(output).stem().string() + ".raw")).string(),
                        {request.input}, rules);
    format::ReadOptions readOptions;
    readOptions.frame = request.frame;
    readOptions.parallel = util::tbbParallelFor();  // predicted windows on every core
    readOptions.keepValueWindows = dense;  // a scan is written window by window when it can be
    readOptions.signedFillLayer = dense;   // a .vdb's inside is filled from the decoded active voxels (pipeline::decodeGrid)
    // A .vdb decode builds OpenVDB's grid beside the decoded values: one more copy of each.
    readOptions.limits = request.limits;
    readOptions.limits.valueCopies = dense ? 0 : 1;
    Volume volume;
    // Steps of a .vdb decode, in thousandths: reading (50), decoding the
    // grids (450, by active voxels), building OpenVDB's grids and
    // writing the file (500, by grid and a last step for the write), so
    // the ETA moves with the work, not from 0% to 100%.
    Progress progress("decode: reading " + std::filesystem::path(request.input).filename().string(), 1000);
    {
        const format::SsvdagScene scene = format::readSceneFile(request.input, readOptions);
        gridCount = scene.grids.size();
        for (const auto& g : scene.grids) activeVoxels += g.active.voxels;
        if (dense && decodeDenseByCubes(scene, request.input, output, request.grid, denseOptions, notes)) return result();
        progress.set(50);
        uint64_t voxels = 0, done = 0;
        for (const auto& g : scene.grids) voxels += g.active.voxels + g.inactive.voxels;
        volume = pipeline::decodeScene(scene, [&](size_t i, size_t) {
            if (i > 0) done += scene.grids[i - 1].active.voxels + scene.grids[i - 1].inactive.voxels;
            progress.setLabel("decode: grid '" + scene.grids[i].record.name + "'");
            progress.set(50 + 450 * done / std::max<uint64_t>(voxels, 1));
        });
        progress.set(500);
    }  // the scene is released before the output is built
    progress.setLabel("decode: writing " + std::filesystem::path(output).filename().string());
    if (dense) {
        // The volumes of a 4-D scan go back as one file; else one grid.
        if (const auto series = request.grid.empty() ? bridge::volumeSeriesOf(volume.grids) : std::nullopt) {
            std::vector<const GridRecord*> volumes;
            for (size_t i : *series) volumes.push_back(&volume.grids[i]);
            notes = bridge::exportDenseVolumes(volumes, output, denseOptions).notes;
        } else {
            notes = bridge::exportDense(denseGridOf(volume.grids, request.input, request.grid, [](const GridRecord& g) { return g.name; }), output, denseOptions).notes;
        }
    }
    else if (nano) bridge::exportNanoVdb(volume, output, [&](size_t step, size_t steps) { progress.set(500 + 500 * step / steps); });
    else bridge::exportVdb(volume, output, [&](size_t step, size_t steps) { progress.set(500 + 500 * step / steps); });
    progress.finish();
    return result();
}


nlohmann::json decodeFiles(const DecodeRequest& request, const std::string& frames,
                           const std::function<void(const std::string& output, const DecodeResult&)>& onFile) {
    const std::vector<FrameJob> jobs = frameJobs({request.input, request.output, frames, "--frames", "file",
                                                  "write them with a frame token in -o (out.####.vdb, out.%04d.vdb) or pick one with --frames N"},
                                                 format::readFrameList(request.input));
    const auto decodeJob = [&](const FrameJob& job) {
        DecodeRequest one = request;
        one.output = job.output, one.frame = job.index;
        DecodeResult result = decodeFile(one);
        if (job.index) result.report["frame"] = job.number;
        if (onFile) onFile(job.output, result);
        return std::move(result.report);
    };
    if (jobs.size() == 1 && jobs.front().output == request.output) {  // one output: a file of one volume, or one frame to the output itself
        nlohmann::json report = decodeJob(jobs.front());
        if (jobs.front().index) report.erase("frame");
        return report;
    }
    for (const FrameJob& job : jobs)
        checkOutputPath(job.output, {request.input}, {{".vdb", ".nvdb", ".nrrd", ".nhdr", ".mha", ".mhd", ".nii", ".gz", ".raw"}, "decode", request.force});
    nlohmann::json reports = nlohmann::json::array();
    for (const FrameJob& job : jobs) reports.push_back(decodeJob(job));
    return reports;
}

} // namespace vdbdag::app
