// `vdbdag verify IN.vdb [--json]`: encode, write the container in memory,
// read it back, decode, and compare with the original file using OpenVDB
// alone (vdb_bridge/VdbCompare): headers, topology, every active value and
// every stored inactive value, bit for bit. Exit 0 only if identical.
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "cli/RunContext.h"
#include "src/pipeline/GridCodec.h"
#include "vdb_bridge/VdbCompare.h"
#include "vdb_bridge/VdbImport.h"

namespace vdbdag::cli {

void addVerifyCommand(CLI::App& app, int& exitCode) {
    struct Options { std::string input; std::vector<std::string> grids; bool json = false, noSymmetry = false, topologyOnly = false; };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("verify", "Round-trip a .vdb file through the .ssvdag format in memory and compare");
    cmd->add_option("input", opt->input, "input .vdb file")->required();
    cmd->add_flag("--no-symmetry", opt->noSymmetry, "verify the plain SVDAG encoding");
    cmd->add_flag("--topology-only", opt->topologyOnly, "verify the geometry-only encoding (topology and headers)");
    cmd->add_flag("--json", opt->json, "print JSON");
    cmd->callback([opt, &exitCode] {
        setActivity(opt->input, "verifying");
        bridge::ImportOptions importOptions;
        importOptions.topologyOnly = opt->topologyOnly;
        const bridge::ImportResult imported = bridge::importVdb(opt->input, importOptions);
        pipeline::EncodeOptions options;
        options.symmetry = !opt->noSymmetry;
        const std::vector<uint8_t> bytes = format::writeScene(pipeline::encodeVolume(imported.volume, options));
        const Volume decoded = pipeline::decodeScene(format::readScene(bytes, opt->input + " (in memory)"));
        const bridge::CompareResult result = bridge::compareWithFile(opt->input, decoded, !opt->topologyOnly);

        nlohmann::json report{{"input", opt->input}, {"identical", result.identical}, {"ssvdag_bytes", bytes.size()},
                              {"header_differences", result.headerDifferences}, {"grids", nlohmann::json::array()}};
        for (const auto& d : result.topology)
            report["grids"].push_back({{"index", d.gridIndex}, {"name", d.gridName}, {"only_in_original", d.onlyInA},
                                       {"only_in_decoded", d.onlyInB}, {"examples", d.examples}});
        report["values"] = nlohmann::json::array();
        for (const auto& d : result.values)
            report["values"].push_back({{"index", d.gridIndex}, {"name", d.gridName}, {"active_values_differing", d.activeValues},
                                        {"inactive_values_differing", d.inactiveValues}, {"examples", d.examples}});
        if (opt->json) {
            fmt::print("{}\n", report.dump(2));
        } else if (result.identical) {
            fmt::print("{}: identical after the round trip ({} grid(s), {} bytes encoded)\n", opt->input, decoded.grids.size(), bytes.size());
        } else {
            fmt::print("{}: DIFFERS after the round trip\n", opt->input);
            for (const auto& h : result.headerDifferences) fmt::print("  {}\n", h);
            for (const auto& d : result.topology) {
                fmt::print("  grid {} '{}': {} voxels only in the original, {} only in the decoded grid\n", d.gridIndex, d.gridName, d.onlyInA, d.onlyInB);
                for (const auto& e : d.examples) fmt::print("    {}\n", e);
            }
            for (const auto& d : result.values) {
                fmt::print("  grid {} '{}': {} active and {} inactive values differ\n", d.gridIndex, d.gridName, d.activeValues, d.inactiveValues);
                for (const auto& e : d.examples) fmt::print("    {}\n", e);
            }
        }
        exitCode = result.identical ? 0 : 1;
    });
}

} // namespace vdbdag::cli
