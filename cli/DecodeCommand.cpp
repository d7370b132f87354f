// `vdbdag decode IN.ssvdag -o OUT.vdb`, or to a dense scan file
// (OUT.nrrd|.nhdr|.mha|.mhd|.nii|.nii.gz|.raw) with the scan's own sample
// type, extent and patient space (vdb_bridge/DenseExport.h).
#include <filesystem>
#include <optional>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "app/DecodeFile.h"
#include "cli/Commands.h"
#include "cli/JsonReport.h"
#include "cli/ReadLimitOptions.h"
#include "cli/RunContext.h"
#include "src/format/FrameSequence.h"
#include "src/util/OutputPath.h"
#include "src/util/Progress.h"

namespace vdbdag::cli {
namespace {

struct DecodeOptions {
    std::string input, output, grid, frames;
    bool force = false, storedValues = false, json = false;
    ReadLimitOptions limits;
};

// "IN -> OUT: N grid(s), V active voxels, B bytes in S s", one output's report.
std::string fileLine(const DecodeOptions& opt, const std::string& output, const nlohmann::json& report) {
    return fmt::format("{} -> {}: {} grid(s), {} active voxels, {} bytes in {:.2f} s\n", opt.input, output, report["grids"].get<size_t>(),
                       report["active_voxels"].get<uint64_t>(), report["output_bytes"].get<uint64_t>(), report["seconds"].get<double>());
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
        setActivity(opt->input, "decoding");
        app::DecodeRequest request;
        request.input = opt->input, request.output = opt->output, request.grid = opt->grid;
        request.force = opt->force, request.storedValues = opt->storedValues;
        request.limits = opt->limits.limits(0);
        const nlohmann::json report = app::decodeFiles(request, opt->frames, [&](const std::string& output, const app::DecodeResult& result) {
            // What changed on the way out, one line each (not silenced by -q: a value written otherwise than stored).
            for (const std::string& n : result.notes) fmt::print(stderr, "{}: note: {}\n", output, n);
            if (!opt->json) fmt::print("{}", fileLine(*opt, output, result.report));
        });
        if (opt->json) printJson(report);
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
