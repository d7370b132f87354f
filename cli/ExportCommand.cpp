// `vdbdag export IN.vdb|IN.ssvdag -o OUT.vtu|OUT.vti|OUT.vtm [--grid NAME]...
// [--bbox X0,Y0,Z0,X1,Y1,Z1]`: VTK XML for ParaView (vdb_bridge/VtkExport);
// with --structure, the DAG's levels and sharing (vdb_bridge/VtkStructure).
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/ByteSize.h"
#include "cli/Commands.h"
#include "cli/JsonReport.h"
#include "cli/ReadLimitOptions.h"
#include "cli/RunContext.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "src/util/Progress.h"
#include "vdb_bridge/VtkExport.h"
#include "vdb_bridge/VtkStructure.h"

namespace vdbdag::cli {
namespace {

std::array<int32_t, 6> parseBox(const std::string& text) {
    std::array<int32_t, 6> box{};
    size_t start = 0;
    for (int i = 0; i < 6; ++i) {
        const size_t comma = text.find(',', start);
        if ((i < 5) != (comma != std::string::npos)) throw Error("--bbox '" + text + "': expected six integers X0,Y0,Z0,X1,Y1,Z1");
        const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        try {
            size_t used = 0;
            const long long v = std::stoll(part, &used);
            if (used != part.size() || v < std::numeric_limits<int32_t>::min() || v > std::numeric_limits<int32_t>::max()) throw std::invalid_argument(part);
            box[size_t(i)] = int32_t(v);
        } catch (const std::exception&) {
            throw Error("--bbox '" + text + "': '" + part + "' is not a 32-bit integer (expected X0,Y0,Z0,X1,Y1,Z1 in index space)");
        }
        start = comma + 1;
    }
    return box;
}

} // namespace

void addExportCommand(CLI::App& app, int& exitCode) {
    struct Options {
        std::string input, output, bbox, compressor = "zlib";
        std::vector<std::string> grids;
        bool structure = false, uniqueNodes = false, json = false, force = false;
        uint64_t maxCells = 20'000'000, maxBytes = uint64_t(256) << 20, maxInstances = 4'000'000;
        ReadLimitOptions limits;
    };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("export", "Write VTK XML for ParaView: active voxels (.vtu), a dense region (.vti), several grids (.vtm), "
                                                 "or with --structure the DAG's levels (.vtm)");
    cmd->add_option("input", opt->input, "input .vdb or .ssvdag file")->required();
    cmd->add_option("-o,--output", opt->output, "output .vtu, .vti or .vtm")->required();
    cmd->add_option("--grid", opt->grids, "export only the grids with this name (repeatable)");
    cmd->add_option("--bbox", opt->bbox, "index-space box X0,Y0,Z0,X1,Y1,Z1 (inclusive): clip, and in a .vtm write it as an image");
    cmd->add_option("--max-cells", opt->maxCells, "stop if an unstructured block would exceed this many cells")->capture_default_str();
    cmd->add_option("--max-bytes", opt->maxBytes, "stop if an image block would exceed this many bytes, e.g. 600M")->capture_default_str()->transform(byteSize());
    cmd->add_option("--compressor", opt->compressor, "zlib or lz4")->capture_default_str();
    cmd->add_flag("--structure", opt->structure, "write the DAG's structure: a block per level, a cell per node instance");
    cmd->add_option("--max-instances", opt->maxInstances, "--structure: past this many instances, write one cell per unique node")->capture_default_str();
    cmd->add_flag("--unique-nodes", opt->uniqueNodes, "--structure: one cell per unique node (at its first instance) with its instance count");
    cmd->add_flag("-f,--force", opt->force, "replace an existing output file (never an input, a link or a device)");
    cmd->add_flag("--json", opt->json, "print the summary as JSON");
    opt->limits.add(*cmd);
    cmd->callback([opt, &exitCode] {
        setActivity(opt->input, "exporting");
        if (opt->json) setQuiet(true);
        checkOutputPath(opt->output, {opt->input}, {opt->structure ? std::vector<std::string>{".vtm"} : std::vector<std::string>{".vtu", ".vti", ".vtm"}, "export", opt->force});
        nlohmann::json report{{"input", opt->input}, {"output", opt->output}};
        if (opt->structure) {
            if (!opt->bbox.empty()) throw Error("--bbox does not apply to --structure");
            bridge::StructureExportOptions options;
            options.grids = opt->grids;
            options.maxInstances = opt->maxInstances;
            options.uniqueNodes = opt->uniqueNodes;
            options.compressor = opt->compressor;
            options.limits = opt->limits.limits(0);
            const bridge::StructureExportReport r = bridge::exportStructure(opt->input, opt->output, options);
            report["bytes"] = r.bytes;
            report["grids"] = nlohmann::json::array();
            for (const auto& g : r.grids) {
                nlohmann::json j{{"name", g.grid}, {"index", g.fileIndex}, {"per_instance", g.perInstance}, {"levels", nlohmann::json::array()}};
                for (const auto& l : g.levels)
                    j["levels"].push_back({{"node_size", l.nodeSize}, {"unique_nodes", l.uniqueNodes}, {"instances", l.instances}, {"cells", l.cells}});
                report["grids"].push_back(j);
            }
            if (opt->json) {
                printJson(report);
            } else {
                fmt::print("{} -> {} ({} bytes)\n", opt->input, opt->output, r.bytes);
                for (const auto& g : r.grids) {
                    fmt::print("  grid '{}': {} per {}\n", g.grid, "a cell", g.perInstance ? "node instance" : "unique node (instance counts in 'instances')");
                    for (const auto& l : g.levels)
                        fmt::print("    {:>7}^3 nodes: {:>10} unique, {:>12} instances, {:>10} cells\n", l.nodeSize, l.uniqueNodes, l.instances, l.cells);
                }
            }
            exitCode = 0;
            return;
        }
        bridge::VtkExportOptions options;
        options.grids = opt->grids;
        if (!opt->bbox.empty()) options.bbox = parseBox(opt->bbox);
        options.maxCells = opt->maxCells;
        options.maxImageBytes = opt->maxBytes;
        options.compressor = opt->compressor;
        options.limits = opt->limits.limits(2);  // OpenVDB's grid and VTK's arrays beside the decoded values
        const bridge::VtkExportReport r = bridge::exportVtk(opt->input, opt->output, options);
        report["bytes"] = r.bytes;
        report["blocks"] = nlohmann::json::array();
        for (const auto& b : r.blocks) {
            nlohmann::json j{{"grid", b.grid}, {"index", b.fileIndex}, {"value_type", b.valueType}, {"kind", b.kind}, {"cells", b.cells}};
            if (b.kind == "image") j["region"] = b.region;
            else j["tile_cells"] = b.tileCells;
            report["blocks"].push_back(j);
        }
        if (opt->json) {
            printJson(report);
        } else {
            fmt::print("{} -> {} ({} bytes)\n", opt->input, opt->output, r.bytes);
            for (const auto& b : r.blocks)
                fmt::print("  grid '{}' ({}): {} {} cells{}\n", b.grid, b.valueType, b.cells, b.kind,
                           b.kind == "image" ? fmt::format(", voxels ({},{},{})..({},{},{})", b.region[0], b.region[1], b.region[2], b.region[3], b.region[4], b.region[5])
                                             : fmt::format(", {} of them whole tiles", b.tileCells));
        }
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
