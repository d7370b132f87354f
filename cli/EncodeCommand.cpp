// `vdbdag encode IN -o OUT.ssvdag [options]`: the options parsed into an
// app::EncodeRequest (app/EncodeFile.h does the work) and the report
// printed; a frame pattern, a folder of frames or a list with -o
// NAME.ssvdag makes one sequence file of every frame; several other inputs
// make one file each.
#include <algorithm>
#include <filesystem>
#include <optional>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "app/EncodeInputs.h"
#include "cli/ByteSize.h"
#include "cli/Commands.h"
#include "cli/DenseInputOptions.h"
#include "cli/FiniteNumber.h"
#include "cli/GlobalOptions.h"
#include "cli/JsonReport.h"
#include "cli/RunContext.h"
#include "app/SceneReport.h"
#include "src/util/Error.h"
#include "src/util/FramePattern.h"
#include "src/util/OutputPath.h"
#include "src/util/Progress.h"
#include "vdb_bridge/DenseImport.h"

namespace vdbdag::cli {
namespace {
// "OUT: N grid(s), V active voxels -> B bytes (...) in S s", one file's report.
std::string fileLine(const nlohmann::json& report) {
    return fmt::format("{}: {} grid(s), {} active voxels -> {} bytes ({:.3f} bits/active voxel) in {:.2f} s\n", report["output"].get<std::string>(),
                       report["grid_count"].get<size_t>(), report["active_voxels"].get<uint64_t>(), report["bytes"].get<uint64_t>(),
                       report["bits_per_active_voxel"].get<double>(), report["seconds"].get<double>());
}
} // namespace

void addEncodeCommand(CLI::App& app, int& exitCode) {
    struct Options {
        std::vector<std::string> inputs;
        std::string output;
        std::vector<std::string> grids;
        bool force = false, noSymmetry = false, noCompress = false, noPredict = false, skipUnsupported = false, json = false, topologyOnly = false;
        bool svdagStats = false;
        int placementTrials = 1;
        unsigned keyEvery = vdbdag::pipeline::kDefaultKeyEvery;
        uint64_t memoryLimit = 0;
        std::string scratch;
        unsigned threads = 0;
        double absError = 0, relError = 0;
        unsigned colourBits = 0, normalBits = 0;
        std::vector<std::string> colourGrids;
        std::string normalGrid;
        DenseInputOptions dense;
    };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("encode", "Encode the grids of a .vdb or NanoVDB .nvdb file (or a dense .raw/.nrrd/.nhdr/.mhd/.mha/.nii scan, or one DICOM series) into an .ssvdag file");
    cmd->add_option("input", opt->inputs,
                    "input .vdb or .nvdb file or dense scan, or DICOM input (folders, .dcm files, DICOMDIRs: several are read as one set); "
                    "a frame pattern (smoke.####.vdb, smoke.%04d.vdb, smoke.$F4.vdb) or several other inputs with -o NAME.ssvdag: one sequence file "
                    "holding every frame; several other inputs otherwise: one .ssvdag each, in the folder -o names or beside each")
        ->required();
    cmd->add_option("-o,--output", opt->output, "output .ssvdag file (default: the input's name with .ssvdag, beside it: ct.nii.gz -> ct.ssvdag, a DICOM folder dir/ -> dir.ssvdag)");
    cmd->add_flag("-f,--force", opt->force, "replace an existing output file (never an input, a link or a device)");
    cmd->add_option("--grid", opt->grids, "encode only grids with this name (repeatable)");
    cmd->add_flag("--no-symmetry", opt->noSymmetry, "plain SVDAG: merge identical subtrees only");
    cmd->add_flag("--no-compress", opt->noCompress, "store sections without zstd");
    cmd->add_flag("--no-predict", opt->noPredict, "integer values: always palettes, never the brick predictor");
    cmd->add_flag("--svdag-stats", opt->svdagStats,
                  "also reduce each layer without symmetry and store the plain SVDAG's node counts, which `info` shows beside the SVO's and "
                  "SSVDAG's (a second reduction; `info IN.vdb` computes them anyway)");
    cmd->add_option("--placement-trials", opt->placementTrials, "root placements to try, keeping the one whose file is smallest; each codes the values again (1-64)")->check(CLI::Range(1, 64));
    cmd->add_option("--key-every", opt->keyEvery,
                    "a 4-D scan (one grid a volume): a key volume every N, coded alone; each other volume's values may take the volume before "
                    "as their reference, where that is smaller (lossless only); a reader decodes at most N - 1 other volumes to reach one "
                    "(1: every volume alone)")
        ->check(CLI::Range(1u, 256u));
    cmd->add_flag("--skip-unsupported", opt->skipUnsupported, "skip grids of unsupported types (e.g. PointDataGrid) instead of failing");
    cmd->add_flag("--topology-only", opt->topologyOnly, "geometry only: active topology as a mask, no values (decodes to MaskGrids)");
    auto* abs = cmd->add_option("--abs-error", opt->absError, "lossy: every float/double active value within this absolute error; an int32/int64 value within its integer part (JPEG-LS NEAR)")->check(finiteNumber())->check(CLI::PositiveNumber);
    cmd->add_option("--rel-error", opt->relError, "lossy: every float/double active value within this relative error")->check(finiteNumber())->check(CLI::Range(1e-12, 0.5))->excludes(abs);
    auto* colourBits = cmd->add_option("--colour-bits,--color-bits", opt->colourBits,
                                       "lossy colours: at most 2^K colours per colour grid, clustered in CIELAB (K = 10, 12, 14; 1..16)")
                           ->check(CLI::Range(1, 16));
    cmd->add_option("--colour-grid,--color-grid", opt->colourGrids, "vec3 grid holding colours (repeatable; default: grids named Cd, color, colour, colorGrid, rgb)")
        ->needs(colourBits);
    auto* normals = cmd->add_option("--normals", opt->normalBits, "store K-bit octahedral normals (K = 10, 12, 16, 24, 32) from the level-set gradient")
                        ->check(CLI::IsMember({10u, 12u, 16u, 24u, 32u}));
    cmd->add_option("--normal-grid", opt->normalGrid, "take the normals from this vec3 grid (stored on its geometry) instead of a gradient")->needs(normals);
    cmd->add_option("--memory-limit", opt->memoryLimit,
                    "working memory for the cubes being encoded, e.g. 512M or 4G (default: half the physical memory); "
                    "a .vdb is read region by region, a scan's samples go to a scratch file; the output is the same bytes")
        ->transform(byteSize());
    cmd->add_option("--scratch", opt->scratch, "folder for the scratch files of a region-by-region encode: the input's bricks and the coded values (default: the output's folder)")
        ->check(CLI::ExistingDirectory);
    cmd->add_option("--threads", opt->threads, "worker threads (default: one per core); the output is the same bytes")->check(CLI::Range(1u, 1024u));
    cmd->add_flag("--json", opt->json, "print the summary as JSON");
    opt->dense.addTo(*cmd);
    cmd->callback([opt, &exitCode] {
        exitCode = 0;
        app::EncodeInputsRequest request;
        request.inputs = opt->inputs, request.output = opt->output, request.dense = opt->dense.inputs();
        app::EncodeRequest& c = request.coding;
        c.force = opt->force, c.grids = opt->grids, c.skipUnsupported = opt->skipUnsupported, c.topologyOnly = opt->topologyOnly;
        c.noSymmetry = opt->noSymmetry, c.noCompress = opt->noCompress, c.noPredict = opt->noPredict, c.svdagStats = opt->svdagStats;
        c.placementTrials = opt->placementTrials, c.keyEvery = opt->keyEvery, c.absError = opt->absError, c.relError = opt->relError;
        c.colourBits = opt->colourBits, c.normalBits = opt->normalBits, c.colourGrids = opt->colourGrids, c.normalGrid = opt->normalGrid;
        c.memoryLimit = opt->memoryLimit, c.scratch = opt->scratch, c.threads = opt->threads;
        app::EncodeInputsHooks hooks;
        hooks.file.team = &cubeTeam();
        hooks.file.warning = [](const std::string& w) { fmt::print(stderr, "vdbdag: warning: {}\n", w); };
        hooks.file.note = [](const std::string& n) { note(n); };
        hooks.onInput = [](const std::string& input) { setActivity(input, "encoding"); };
        hooks.onFile = [opt](const nlohmann::json& report) {
            if (!opt->json) fmt::print("{}", fileLine(report));
        };
        const app::EncodeInputsResult result = app::encodeInputs(request, hooks);
        if (!result.written) return;  // another process of the team writes and reports
        const nlohmann::json& r = result.report;
        if (opt->json) {
            printJson(r);
        } else if (result.shape == app::EncodeShape::Sequence) {
            const std::vector<FrameFile>& frames = result.frames;
            fmt::print("{}: {} frames ({} to {}), {} active voxels -> {} bytes ({:.3f} bits/active voxel; the frames alone {} bytes) in {:.2f} s\n",
                       result.output, frames.size(), frames.front().number, frames.back().number, r["active_voxels"].get<uint64_t>(),
                       r["bytes"].get<uint64_t>(), r["bits_per_active_voxel"].get<double>(), r["frame_files_bytes"].get<uint64_t>(), r["seconds"].get<double>());
        } else if (result.shape == app::EncodeShape::OneFile) {
            fmt::print("{}{}", fileLine(r), thresholdText(result.threshold));
            for (const auto& l : r["grids_lossy"])
                fmt::print("  grid '{}' {}: {} of {} values changed, max error {:.3g}, mean {:.3g}, RMS {:.3g}, max relative {:.3g}\n",
                           l["name"].get<std::string>(), l["tolerance"].get<std::string>(), l["changed"].get<uint64_t>(), l["entries"].get<uint64_t>(),
                           l["max_abs_error"].get<double>(), l["mean_abs_error"].get<double>(), l["rms_error"].get<double>(), l["max_rel_error"].get<double>());
            for (const auto& colour : r["grids_colour"]) fmt::print("  {}\n", app::formatColour(colour));
            for (const auto& n : r["grids_normals"]) fmt::print("  {}\n", app::formatNormals(n));
        }
    });
}

} // namespace vdbdag::cli
