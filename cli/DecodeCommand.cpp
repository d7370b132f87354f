// `vdbdag decode IN.ssvdag -o OUT.vdb`, or to a dense scan file
// (OUT.nrrd|.nhdr|.mha|.mhd|.nii|.nii.gz|.raw) with the scan's own sample
// type, extent and patient space (vdb_bridge/DenseExport.h).
#include <filesystem>

#include <fmt/core.h>

#include "cli/Commands.h"
#include "cli/RunContext.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "src/util/Progress.h"
#include "vdb_bridge/DenseExport.h"
#include "vdb_bridge/VdbExport.h"

namespace vdbdag::cli {
namespace {

// The grid a dense output takes: the one named, or the file's only grid.
const GridRecord& denseGridOf(const Volume& volume, const std::string& input, const std::string& name) {
    if (!name.empty()) {
        for (const GridRecord& g : volume.grids)
            if (g.name == name) return g;
        throw Error(input + ": has no grid named '" + name + "'");
    }
    if (volume.grids.size() != 1) {
        std::string names;
        for (const GridRecord& g : volume.grids) names += (names.empty() ? "'" : ", '") + g.name + "'";
        throw Error(input + ": holds " + std::to_string(volume.grids.size()) + " grids (" + names +
                    "); a scan file holds one: pick it with --grid NAME");
    }
    return volume.grids.front();
}

} // namespace

void addDecodeCommand(CLI::App& app, int& exitCode) {
    struct Options {
        std::string input, output, grid;
        bool force = false;
    };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("decode", "Decode an .ssvdag file back into a .vdb file, or a dense grid into a scan file");
    cmd->add_option("input", opt->input, "input .ssvdag file")->required();
    cmd->add_option("-o,--output", opt->output, "output .vdb, or .nrrd/.nhdr/.mha/.mhd/.nii/.nii.gz/.raw for a dense scan")->required();
    cmd->add_option("--grid", opt->grid, "scan output: the grid to write (default: the file's only grid)");
    cmd->add_flag("-f,--force", opt->force, "replace an existing output file (never an input, a link or a device)");
    cmd->callback([opt, &exitCode] {
        setActivity(opt->input, "decoding");
        const bool dense = bridge::isDenseOutput(opt->output);
        if (!dense && lowerExtension(opt->output) != ".vdb")
            throw Error(opt->output + ": decode writes .vdb, or a dense scan as .nrrd, .nhdr, .mha, .mhd, .nii, .nii.gz or .raw");
        if (!dense && !opt->grid.empty()) throw Error(opt->output + ": --grid applies to scan outputs (a .vdb file takes every grid)");
        const OutputRules rules{{".vdb", ".nrrd", ".nhdr", ".mha", ".mhd", ".nii", ".gz", ".raw"}, "decode", opt->force};
        checkOutputPath(opt->output, {opt->input}, rules);
        const std::string ext = lowerExtension(opt->output);
        if (ext == ".nhdr" || ext == ".mhd")  // their samples go beside them, as NAME.raw
            checkOutputPath((std::filesystem::path(opt->output).parent_path() / (std::filesystem::path(opt->output).stem().string() + ".raw")).string(),
                            {opt->input}, rules);
        format::ReadOptions readOptions;
        readOptions.rebuildPalettes = false;  // only the values are needed
        Volume volume;
        {
            const format::SsvdagScene scene = format::readSceneFile(opt->input, readOptions);
            Progress progress("decode", scene.grids.size());
            volume = pipeline::decodeScene(scene, [&](size_t i, size_t) { progress.set(i); });
            progress.finish();
        }  // the scene is released before the output is built
        if (dense) bridge::exportDense(denseGridOf(volume, opt->input, opt->grid), opt->output);
        else bridge::exportVdb(volume, opt->output);
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
