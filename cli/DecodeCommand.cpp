// `vdbdag decode IN.ssvdag -o OUT.vdb`, or to a dense scan file
// (OUT.nrrd|.nhdr|.mha|.mhd|.nii|.nii.gz|.raw) with the scan's own sample
// type, extent and patient space (vdb_bridge/DenseExport.h).
#include <chrono>
#include <filesystem>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "cli/FrameJobs.h"
#include "cli/JsonReport.h"
#include "cli/ReadLimitOptions.h"
#include "cli/RunContext.h"
#include "src/pipeline/GridCodec.h"
#include "src/pipeline/LayerScatter.h"
#include "src/util/Error.h"
#include "src/format/FrameSequence.h"
#include "src/util/OutputPath.h"
#include "src/util/Progress.h"
#include "src/util/ParallelFor.h"
#include "vdb_bridge/DenseExport.h"
#include "vdb_bridge/NanoVdb.h"
#include "vdb_bridge/VdbExport.h"

namespace vdbdag::cli {
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
    const encoding::CompactDag& active = grid.dag;
    const uint64_t total = (grid.inactiveDag.empty() ? 0 : 1) + (active.empty() ? 0 : 1);
    Progress progress("decode " + std::filesystem::path(output).filename().string(), 1000 * std::max<uint64_t>(total, 1));
    const bridge::DenseExportReport report = bridge::exportDenseByCubes(grid.record, output, [&](bridge::DenseCubeSink& sink) {
        uint64_t layer = 0;
        for (const bool inactive : {true, false}) {  // inactive first: active voxels win
            if ((inactive ? grid.inactiveDag : active).empty()) continue;
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

struct DecodeOptions {
    std::string input, output, grid, frames;
    bool force = false, storedValues = false, json = false;
    ReadLimitOptions limits;
};

// One volume of the input (the whole file, or frame `frame` of a sequence)
// to `output`; its report goes to `batch` when given, else is printed.
void decodeOne(const DecodeOptions& opt, const std::string& output, std::optional<uint32_t> frame, nlohmann::json* batch) {
    setActivity(opt.input, "decoding");
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::string> notes;
    size_t gridCount = 0;
    uint64_t activeVoxels = 0;
    // The summary line (or JSON) once the output is in place, as encode prints one.
    auto summary = [&] {
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::error_code ec;
        const uint64_t bytes = std::filesystem::file_size(output, ec);
        const nlohmann::json report{{"input", opt.input}, {"output", output}, {"grids", gridCount}, {"active_voxels", activeVoxels},
                                    {"output_bytes", ec ? 0 : bytes}, {"seconds", seconds}, {"notes", notes}};
        if (batch) batch->push_back(report);
        else if (opt.json) printJson(report);
        if (!opt.json) fmt::print("{} -> {}: {} grid(s), {} active voxels, {} bytes in {:.2f} s\n", opt.input, output, gridCount, activeVoxels,
                        ec ? 0 : bytes, seconds);
    };
    const bool dense = bridge::isDenseOutput(output);
    const bool nano = lowerExtension(output) == ".nvdb";
    if (!dense && !nano && lowerExtension(output) != ".vdb")
        throw Error(output + ": decode writes .vdb or .nvdb, or a dense scan as .nrrd, .nhdr, .mha, .mhd, .nii, .nii.gz or .raw");
    if (!dense && !opt.grid.empty()) throw Error(output + ": --grid applies to scan outputs (a .vdb or .nvdb file takes every grid)");
    if (!dense && opt.storedValues) throw Error(output + ": --stored-values applies to scan outputs (a .vdb or .nvdb file holds the grid's values)");
    bridge::DenseExportOptions denseOptions;
    denseOptions.storedValues = opt.storedValues;
    // What changed on the way out, one line each (not silenced by -q: a value written otherwise than stored).
    auto printNotes = [&] {
        for (const std::string& n : notes) fmt::print(stderr, "{}: note: {}\n", output, n);
    };
    const OutputRules rules{{".vdb", ".nvdb", ".nrrd", ".nhdr", ".mha", ".mhd", ".nii", ".gz", ".raw"}, "decode", opt.force};
    checkOutputPath(output, {opt.input}, rules);
    const std::string ext = lowerExtension(output);
    if (ext == ".nhdr" || ext == ".mhd")  // their samples go beside them, as NAME.raw
        checkOutputPath((std::filesystem::path(output).parent_path() / (std::filesystem::path(output).stem().string() + ".raw")).string(),
                        {opt.input}, rules);
    format::ReadOptions readOptions;
    readOptions.frame = frame;
    readOptions.parallel = util::tbbParallelFor();  // predicted windows on every core
    readOptions.keepValueWindows = dense;  // a scan is written window by window when it can be
    // A .vdb decode builds OpenVDB's grid beside the decoded values: one more copy of each.
    readOptions.limits = opt.limits.limits(dense ? 0 : 1);
    Volume volume;
    // Steps of a .vdb decode, in thousandths: reading (50), decoding the
    // grids (450, by active voxels), building OpenVDB's grids and
    // writing the file (500, by grid and a last step for the write), so
    // the ETA moves with the work, not from 0% to 100%.
    Progress progress("decode: reading " + std::filesystem::path(opt.input).filename().string(), 1000);
    {
        const format::SsvdagScene scene = format::readSceneFile(opt.input, readOptions);
        gridCount = scene.grids.size();
        for (const auto& g : scene.grids) activeVoxels += g.activeVoxels;
        if (dense && decodeDenseByCubes(scene, opt.input, output, opt.grid, denseOptions, notes)) {
            printNotes();
            summary();
            return;
        }
        progress.set(50);
        uint64_t voxels = 0, done = 0;
        for (const auto& g : scene.grids) voxels += g.activeVoxels + g.inactiveVoxels;
        volume = pipeline::decodeScene(scene, [&](size_t i, size_t) {
            if (i > 0) done += scene.grids[i - 1].activeVoxels + scene.grids[i - 1].inactiveVoxels;
            progress.setLabel("decode: grid '" + scene.grids[i].record.name + "'");
            progress.set(50 + 450 * done / std::max<uint64_t>(voxels, 1));
        });
        progress.set(500);
    }  // the scene is released before the output is built
    progress.setLabel("decode: writing " + std::filesystem::path(output).filename().string());
    if (dense) {
        // The volumes of a 4-D scan go back as one file; else one grid.
        if (const auto series = opt.grid.empty() ? bridge::volumeSeriesOf(volume.grids) : std::nullopt) {
            std::vector<const GridRecord*> volumes;
            for (size_t i : *series) volumes.push_back(&volume.grids[i]);
            notes = bridge::exportDenseVolumes(volumes, output, denseOptions).notes;
        } else {
            notes = bridge::exportDense(denseGridOf(volume.grids, opt.input, opt.grid, [](const GridRecord& g) { return g.name; }), output, denseOptions).notes;
        }
    }
    else if (nano) bridge::exportNanoVdb(volume, output, [&](size_t step, size_t steps) { progress.set(500 + 500 * step / steps); });
    else bridge::exportVdb(volume, output, [&](size_t step, size_t steps) { progress.set(500 + 500 * step / steps); });
    progress.finish();
    printNotes();
    summary();
}

} // namespace

void addDecodeCommand(CLI::App& app, int& exitCode) {
    auto opt = std::make_shared<DecodeOptions>();
    CLI::App* cmd = app.add_subcommand("decode", "Decode an .ssvdag file back into a .vdb (or NanoVDB .nvdb) file, or a dense grid into a scan file");
    cmd->add_option("input", opt->input, "input .ssvdag file")->required();
    cmd->add_option("-o,--output", opt->output, "output .vdb or .nvdb, or .nrrd/.nhdr/.mha/.mhd/.nii/.nii.gz/.raw for a dense scan")->required();
    cmd->add_option("--grid", opt->grid, "scan output: the grid to write (default: the file's only grid)");
    cmd->add_flag("--stored-values", opt->storedValues,
                  "scan output of a rescaled scan (DICOM, NIfTI scl_slope) to .nrrd/.nhdr/.mha/.mhd/.raw: write the stored integers, with the rescale as "
                  "key/value pairs, instead of the grid's values (NIfTI always holds the stored integers and the rescale)");
    cmd->add_flag("-f,--force", opt->force, "replace an existing output file (never an input, a link or a device)");
    cmd->add_flag("--json", opt->json, "print the summary as JSON");
    cmd->add_option("--frames", opt->frames, "a sequence file: the frames to write (12, 10-20, 1,5,9-12; default: all), each to the file -o names with its number (out.####.vdb)");
    opt->limits.add(*cmd);
    cmd->callback([opt, &exitCode] {
        if (opt->json) setQuiet(true);
        const std::vector<FrameJob> jobs = frameJobs({opt->input, opt->output, opt->frames, "--frames", "file",
                                                      "write them with a frame token in -o (out.####.vdb, out.%04d.vdb) or pick one with --frames N"},
                                                     format::readFrameList(opt->input));
        if (jobs.size() == 1 && jobs.front().output == opt->output) {  // one output: a file of one volume, or one frame to -o itself
            decodeOne(*opt, jobs.front().output, jobs.front().index, nullptr);
            exitCode = 0;
            return;
        }
        // Every output checked before any is written.
        for (const FrameJob& job : jobs) checkOutputPath(job.output, {opt->input}, {{".vdb", ".nvdb", ".nrrd", ".nhdr", ".mha", ".mhd", ".nii", ".gz", ".raw"}, "decode", opt->force});
        nlohmann::json reports = nlohmann::json::array();
        for (const FrameJob& job : jobs) {
            decodeOne(*opt, job.output, job.index, &reports);
            reports.back()["frame"] = job.number;
        }
        if (opt->json) printJson(reports);
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
