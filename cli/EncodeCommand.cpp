// `vdbdag encode IN.vdb -o OUT.ssvdag [--grid NAME]... [--no-symmetry] [--topology-only]`
#include <chrono>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/AtomicFile.h"
#include "src/util/Progress.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::cli {

void addEncodeCommand(CLI::App& app, int& exitCode) {
    struct Options {
        std::string input, output;
        std::vector<std::string> grids;
        bool noSymmetry = false, noCompress = false, skipUnsupported = false, json = false, topologyOnly = false;
        int placementTrials = 1;
    };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("encode", "Encode the grids of a .vdb file into an .ssvdag file");
    cmd->add_option("input", opt->input, "input .vdb file")->required();
    cmd->add_option("-o,--output", opt->output, "output .ssvdag file")->required();
    cmd->add_option("--grid", opt->grids, "encode only grids with this name (repeatable)");
    cmd->add_flag("--no-symmetry", opt->noSymmetry, "plain SVDAG: merge identical subtrees only");
    cmd->add_flag("--no-compress", opt->noCompress, "store sections without zstd");
    cmd->add_option("--placement-trials", opt->placementTrials, "root placements to try, keeping the smallest (1-64)")->check(CLI::Range(1, 64));
    cmd->add_flag("--skip-unsupported", opt->skipUnsupported, "skip grids of unsupported types (e.g. PointDataGrid) instead of failing");
    cmd->add_flag("--topology-only", opt->topologyOnly, "geometry only: active topology as a mask, no values (decodes to MaskGrids)");
    cmd->add_flag("--json", opt->json, "print the summary as JSON");
    cmd->callback([opt, &exitCode] {
        const auto start = std::chrono::steady_clock::now();
        bridge::ImportOptions importOptions;
        importOptions.onlyGrids = opt->grids;
        importOptions.skipUnsupported = opt->skipUnsupported;
        importOptions.topologyOnly = opt->topologyOnly;
        const bridge::ImportResult imported = bridge::importVdb(opt->input, importOptions);
        for (const auto& w : imported.warnings) fmt::print(stderr, "vdbdag: warning: {}\n", w);

        pipeline::EncodeOptions encodeOptions;
        encodeOptions.symmetry = !opt->noSymmetry;
        encodeOptions.placementTrials = opt->placementTrials;
        encodeOptions.computeSvdagStats = true;  // cheap next to I/O; lets `info` show all three node counts
        Progress progress("encode", imported.volume.grids.size());
        const format::SsvdagScene scene = pipeline::encodeVolume(imported.volume, encodeOptions, [&](size_t i, size_t) { progress.set(i); });
        progress.finish();
        format::ContainerOptions containerOptions;
        containerOptions.compress = !opt->noCompress;
        const std::vector<uint8_t> bytes = format::writeScene(scene, containerOptions);
        writeFileAtomically(opt->output, bytes);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

        uint64_t voxels = 0;
        for (const auto& g : scene.grids) voxels += g.activeVoxels;
        nlohmann::json report{{"input", opt->input}, {"output", opt->output}, {"bytes", bytes.size()}, {"grids", scene.grids.size()},
                              {"active_voxels", voxels}, {"seconds", seconds},
                              {"bits_per_active_voxel", voxels ? 8.0 * double(bytes.size()) / double(voxels) : 0.0}};
        if (opt->json) {
            fmt::print("{}\n", report.dump(2));
        } else {
            fmt::print("{}: {} grid(s), {} active voxels -> {} bytes ({:.3f} bits/active voxel) in {:.2f} s\n", opt->output,
                       scene.grids.size(), voxels, bytes.size(), report["bits_per_active_voxel"].get<double>(), seconds);
        }
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
