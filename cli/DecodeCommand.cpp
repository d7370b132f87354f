// `vdbdag decode IN.ssvdag -o OUT.vdb`
#include <fmt/core.h>

#include "cli/Commands.h"
#include "cli/RunContext.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/OutputPath.h"
#include "src/util/Progress.h"
#include "vdb_bridge/VdbExport.h"

namespace vdbdag::cli {

void addDecodeCommand(CLI::App& app, int& exitCode) {
    struct Options {
        std::string input, output;
        bool force = false;
    };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("decode", "Decode an .ssvdag file back into a .vdb file");
    cmd->add_option("input", opt->input, "input .ssvdag file")->required();
    cmd->add_option("-o,--output", opt->output, "output .vdb file")->required();
    cmd->add_flag("-f,--force", opt->force, "replace an existing output file (never an input, a link or a device)");
    cmd->callback([opt, &exitCode] {
        setActivity(opt->input, "decoding");
        checkOutputPath(opt->output, {opt->input}, {{".vdb"}, "decode", opt->force});
        format::ReadOptions readOptions;
        readOptions.rebuildPalettes = false;  // only the values are needed
        Volume volume;
        {
            const format::SsvdagScene scene = format::readSceneFile(opt->input, readOptions);
            Progress progress("decode", scene.grids.size());
            volume = pipeline::decodeScene(scene, [&](size_t i, size_t) { progress.set(i); });
            progress.finish();
        }  // the scene is released before OpenVDB builds the grids
        bridge::exportVdb(volume, opt->output);
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
