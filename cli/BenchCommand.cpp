// `vdbdag bench IN.vdb -o REPORT_DIR [--sweep quick|default|full]`: parses
// the request, runs app::runBenchmark (app/Benchmark.h) and writes its report
// (app/BenchReport.h).
#include <filesystem>

#include <fmt/core.h>

#include "app/Benchmark.h"
#include "cli/Commands.h"
#include "cli/JsonReport.h"
#include "src/util/Error.h"
#include "src/util/Progress.h"

namespace vdbdag::cli {

void addBenchCommand(CLI::App& app, int& exitCode) {
    struct Options {
        app::BenchRequest request;
        std::string output;
        bool json = false;
    };
    auto opt = std::make_shared<Options>();
    app::BenchRequest& r = opt->request;
    CLI::App* cmd = app.add_subcommand("bench", "Measure every lossy setting's error against size and run time, beside OpenVDB, NanoVDB and ZFP");
    cmd->add_option("input", r.input, "input .vdb file")->required();
    cmd->add_option("-o,--output", opt->output, "report directory (report.md, report.csv, report.json, plots)")->required();
    cmd->add_option("--sweep", r.sweep, "quick, default or full")->check(CLI::IsMember({"quick", "default", "full"}));
    cmd->add_option("--grid", r.grids, "only these grids (repeatable)");
    cmd->add_option("--width", r.width, "render width for trace time and image error")->check(CLI::Range(16, 4096));
    cmd->add_option("--height", r.height, "render height")->check(CLI::Range(16, 4096));
    cmd->add_option("--repeats", r.repeats, "timed runs per measurement (default: by sweep)")->check(CLI::Range(1, 50));
    cmd->add_option("--time-budget", r.budgetSeconds,
                    "seconds per measurement after which no further repeat is timed (at least one run; default 3)")
        ->check(CLI::Range(0.0, 3600.0));
    cmd->add_flag("--json", opt->json, "print the whole report as JSON on stdout");
    cmd->callback([opt, &exitCode] {
        namespace fs = std::filesystem;
        if (fs::exists(opt->output) && !fs::is_directory(opt->output)) throw Error(opt->output + ": exists and is not a directory");
        if (opt->json) setQuiet(true);
        const app::BenchRun run = app::runBenchmark(opt->request);
        app::writeBenchReport(run, opt->output);
        if (opt->json) printJson(app::benchToJson(run));
        else fmt::print("bench: {} points on {} grid(s) in {:.0f} s -> {}/report.md\n", run.points.size(), run.gridCount, run.seconds, opt->output);
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
