// `vdbdag diff A B [-o DIFF.vtu|DIFF.vtm] [--only-differences] [--json]`:
// voxel-by-voxel comparison (vdb_bridge/VtkDiff); prints counts per status,
// max / mean / RMS error and PSNR; exit 0 when the grids are the same, 1
// when they differ, 2 on an error (as diff and cmp do).
#include <cmath>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "cli/JsonReport.h"
#include "cli/ReadLimitOptions.h"
#include "cli/RunContext.h"
#include "src/util/OutputPath.h"
#include "src/util/Progress.h"
#include "vdb_bridge/VtkDiff.h"

namespace vdbdag::cli {
namespace {

nlohmann::json number(double v) {
    if (std::isnan(v)) return nullptr;
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return v;
}

} // namespace

void addDiffCommand(CLI::App& app, int& exitCode) {
    struct Options {
        std::string a, b, output, compressor = "zlib", pair = "auto";
        std::vector<std::string> grids;
        bool onlyDifferences = false, json = false, force = false;
        uint64_t maxCells = 20'000'000;
        ReadLimitOptions limits;
    };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("diff", "Compare two volumes voxel by voxel (.vdb, .ssvdag or a dense scan); exit 0 if they are the same, 1 if they differ, 2 on an error");
    cmd->add_option("a", opt->a, "first volume (A: the reference)")->required();
    cmd->add_option("b", opt->b, "second volume (B)")->required();
    cmd->add_option("-o,--output", opt->output, "write the cells (a, b, abs_error, rel_error, status) to a .vtu or .vtm");
    cmd->add_option("--grid", opt->grids, "compare only grids with this name (repeatable)");
    cmd->add_option("--pair", opt->pair,
                    "how grids are paired: auto (two single-grid files pair whatever their names, else by name), name (grids of the same name), "
                    "order (in file order)")
        ->check(CLI::IsMember({"auto", "name", "order"}))
        ->capture_default_str();
    cmd->add_flag("--only-differences", opt->onlyDifferences, "write only cells whose status is not 'same'");
    cmd->add_option("--max-cells", opt->maxCells, "stop if a written block would exceed this many cells")->capture_default_str();
    cmd->add_option("--compressor", opt->compressor, "zlib or lz4")->capture_default_str();
    cmd->add_flag("-f,--force", opt->force, "replace an existing output file (never an input, a link or a device)");
    cmd->add_flag("--json", opt->json, "print the report as JSON");
    opt->limits.add(*cmd);
    cmd->callback([opt, &exitCode] {
        setFailureExitCode(2);  // 1 means "they differ", as for diff and cmp
        setActivity(opt->a, "comparing");
        if (opt->json) setQuiet(true);
        if (!opt->output.empty()) checkOutputPath(opt->output, {opt->a, opt->b}, {{".vtu", ".vtm"}, "diff", opt->force});
        bridge::DiffOptions options;
        options.grids = opt->grids;
        options.onlyDifferences = opt->onlyDifferences;
        options.maxCells = opt->maxCells;
        options.compressor = opt->compressor;
        // Each .ssvdag side is decoded, copied into a grid record and built
        // as an OpenVDB grid, and both are held at once: half the memory each.
        options.limits = opt->limits.limits(2);
        options.limits.maxMemory /= 2;
        options.pairing = opt->pair == "name" ? bridge::DiffPairing::Name : opt->pair == "order" ? bridge::DiffPairing::Order : bridge::DiffPairing::Auto;
        const bridge::DiffReport r = bridge::diffVolumes(opt->a, opt->b, opt->output, options);
        static const char* kStatus[4] = {"same", "value_differs", "only_in_a", "only_in_b"};
        nlohmann::json report{{"inputs", {opt->a, opt->b}}, {"a", opt->a}, {"b", opt->b}, {"identical", r.identical}, {"header_differences", r.headerDifferences}, {"notes", r.notes},
                              {"peak", "value range (max - min) of A's active values; vector magnitudes"}, {"grids", nlohmann::json::array()}};
        if (!opt->output.empty()) { report["output"] = opt->output; report["bytes"] = r.bytes; }
        for (const auto& g : r.grids) {
            nlohmann::json counts;
            for (int s = 0; s < 4; ++s) counts[kStatus[s]] = g.voxels[size_t(s)];
            report["grids"].push_back({{"name", g.name}, {"index_a", g.indexA}, {"index_b", g.indexB}, {"value_type", g.valueType}, {"voxels", counts},
                                       {"cells_written", g.cells}, {"non_finite_errors", g.nonFiniteErrors}, {"max_abs_error", g.maxAbsError},
                                       {"mean_abs_error", g.meanAbsError}, {"rms_error", g.rmsError}, {"max_rel_error", g.maxRelError},
                                       {"peak", g.peak}, {"psnr_db", number(g.psnr)},
                                       {"over_all_of_a", {{"voxels", g.ofA.voxels}, {"max_abs_error", g.ofA.maxAbsError}, {"mean_abs_error", g.ofA.meanAbsError},
                                                          {"rms_error", g.ofA.rmsError}, {"psnr_db", number(g.ofA.psnr)}}}});
        }
        if (opt->json) {
            printJson(report);
        } else {
            fmt::print("{} vs {}: {}\n", opt->a, opt->b, r.identical ? "same" : "DIFFER");
            for (const auto& h : r.headerDifferences) fmt::print("  {}\n", h);
            for (const auto& n : r.notes) fmt::print("  note: {}\n", n);
            for (const auto& g : r.grids) {
                fmt::print("  grid '{}' ({}): {} same, {} value differs, {} only in A, {} only in B (voxels)\n", g.name, g.valueType, g.voxels[0],
                           g.voxels[1], g.voxels[2], g.voxels[3]);
                fmt::print("    error over voxels active in both: max {:.6g}, mean {:.6g}, RMS {:.6g}, max relative {:.6g}; PSNR {} (peak {:.6g} = A's value range)\n",
                           g.maxAbsError, g.meanAbsError, g.rmsError, g.maxRelError,
                           std::isinf(g.psnr) ? std::string("inf") : std::isnan(g.psnr) ? std::string("undefined") : fmt::format("{:.2f} dB", g.psnr), g.peak);
                if (g.voxels[2])
                    fmt::print("    error over all of A's voxels (B's inactive value where B has none, e.g. a threshold): max {:.6g}, mean {:.6g}, RMS {:.6g}; PSNR {}\n",
                               g.ofA.maxAbsError, g.ofA.meanAbsError, g.ofA.rmsError,
                               std::isinf(g.ofA.psnr) ? std::string("inf") : std::isnan(g.ofA.psnr) ? std::string("undefined") : fmt::format("{:.2f} dB", g.ofA.psnr));
                if (g.nonFiniteErrors) fmt::print("    {} voxels differ by NaN or inf (not in the statistics)\n", g.nonFiniteErrors);
            }
            if (!opt->output.empty()) fmt::print("  wrote {} ({} bytes)\n", opt->output, r.bytes);
        }
        exitCode = r.identical ? 0 : 1;
    });
}

} // namespace vdbdag::cli
