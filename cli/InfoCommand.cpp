// `vdbdag info FILE [--json]` for .ssvdag files and for .vdb files (which
// are encoded in memory, with the plain-SVDAG reduction run too so all three
// node counts show).
#include <fmt/core.h>

#include "cli/Commands.h"
#include "cli/RunContext.h"
#include "cli/SceneReport.h"
#include "src/pipeline/GridCodec.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::cli {

namespace {
// OpenVDB files start with the int32 magic 0x56444220 ("VDB " read little-endian).
bool isVdbFile(std::span<const uint8_t> bytes) {
    return bytes.size() >= 4 && bytes[0] == 0x20 && bytes[1] == 0x42 && bytes[2] == 0x44 && bytes[3] == 0x56;
}
} // namespace

void addInfoCommand(CLI::App& app, int& exitCode) {
    struct Options { std::string input; bool json = false; bool noSymmetry = false; };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("info", "Print per-grid DAG statistics and section sizes of a .ssvdag or .vdb file");
    cmd->add_option("input", opt->input, ".ssvdag or .vdb file")->required();
    cmd->add_flag("--json", opt->json, "print JSON");
    cmd->add_flag("--no-symmetry", opt->noSymmetry, "for .vdb input: report the plain SVDAG encoding");
    cmd->callback([opt, &exitCode] {
        setActivity(opt->input, "reading");
        std::vector<uint8_t> bytes = format::readFileBytes(opt->input);
        format::SsvdagScene scene;
        if (!isVdbFile(bytes)) {
            scene = format::readScene(bytes, opt->input);
        } else {
            const bridge::ImportResult imported = bridge::importVdb(opt->input);
            pipeline::EncodeOptions options;
            options.symmetry = !opt->noSymmetry;
            options.computeSvdagStats = true;
            scene = pipeline::encodeVolume(imported.volume, options);
            bytes = format::writeScene(scene);
        }
        const nlohmann::json report = sceneReport(scene, bytes, opt->input);
        if (opt->json) fmt::print("{}\n", report.dump(2));
        else fmt::print("{}", formatSceneReport(report));
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
