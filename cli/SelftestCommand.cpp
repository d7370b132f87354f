// `vdbdag selftest [--filter SUBSTR] [--json] [--list] [-v]`: runs the stiff
// and extreme cases of issue 7 part 2 (src/selftest/) and prints each as
// `group/name  bound  measured  PASS|FAIL` with its full figures below, then
// a summary; exit 1 when any case fails. Progress on a terminal (stderr), none when piped or with --json.
#include <algorithm>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "cli/JsonReport.h"
#include "src/selftest/Selftest.h"
#include "src/util/Error.h"
#include "src/util/Progress.h"

namespace vdbdag::cli {
namespace {

// Terminal columns of UTF-8 text (the bounds use ° and Δ): code points.
size_t displayWidth(const std::string& s) {
    size_t n = 0;
    for (unsigned char c : s) n += (c & 0xC0) != 0x80;
    return n;
}

std::string pad(const std::string& s, size_t width) { return s + std::string(width - std::min(width, displayWidth(s)), ' '); }

} // namespace

void addSelftestCommand(CLI::App& app, int& exitCode) {
    struct Options { std::string filter; bool json = false, list = false, verbose = false; };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("selftest", "Run the stiff and extreme cases (values, geometry, colours, normals, rays), each against its bound");
    cmd->add_option("--filter", opt->filter, "run only cases whose group/name contains SUBSTR");
    cmd->add_flag("--list", opt->list, "list the cases and their bounds without running them");
    cmd->add_flag("-v,--verbose", opt->verbose, "print every case's full bound too");
    cmd->add_flag("--json", opt->json, "print JSON");
    cmd->callback([opt, &exitCode] {
        const size_t count = selftest::countSelftestCases(opt->filter);
        if (count == 0) throw Error("selftest: no case matches '" + opt->filter + "' (see `vdbdag selftest --list`)");
        if (opt->list) {
            nlohmann::json list = nlohmann::json::array();
            for (const auto& c : selftest::selftestCases())
                if (opt->filter.empty() || c.id().find(opt->filter) != std::string::npos) {
                    if (opt->json) list.push_back({{"group", c.group}, {"name", c.name}, {"limit", c.limit}, {"bound", c.bound}});
                    else fmt::print("{}  {}\n    {}\n", c.id(), c.limit, c.bound);
                }
            if (opt->json) printJson(list);
            exitCode = 0;
            return;
        }
        if (opt->json) setQuiet(true);
        Progress progress("selftest", count);
        const auto results = selftest::runSelftest(opt->filter, [&](const selftest::CaseResult& r) {
            progress.setLabel("selftest: " + r.id());
            progress.advance();
        });
        progress.finish();
        size_t failed = 0;
        double seconds = 0;
        for (const auto& r : results) failed += !r.passed, seconds += r.seconds;
        if (opt->json) {
            nlohmann::json cases = nlohmann::json::array();
            for (const auto& r : results)
                cases.push_back({{"group", r.group}, {"name", r.name}, {"limit", r.limit}, {"bound", r.bound}, {"value", r.value},
                                 {"measured", r.measured}, {"passed", r.passed}, {"seconds", r.seconds}});
            const nlohmann::json report{{"cases", cases}, {"total", results.size()}, {"passed", results.size() - failed}, {"failed", failed}, {"seconds", seconds}};
            printJson(report);
        } else {
            // One table line per case (group/name, bound, measured, PASS|FAIL), then
            // the full figures indented below it; with --verbose the full bound too.
            size_t wId = 0, wLimit = 0, wValue = 0;
            for (const auto& r : results) {
                wId = std::max(wId, r.id().size());
                wLimit = std::max(wLimit, displayWidth(r.limit));
                wValue = std::max(wValue, displayWidth(r.value));
            }
            fmt::print("{}  {}  {}  result\n", pad("case", wId), pad("bound", wLimit), pad("measured", wValue));
            for (const auto& r : results) {
                fmt::print("{}  {}  {}  {}\n", pad(r.id(), wId), pad(r.limit, wLimit), pad(r.value, wValue), r.passed ? "PASS" : "FAIL");
                if (opt->verbose || !r.passed) fmt::print("    bound:    {}\n", r.bound);
                fmt::print("    measured: {}  ({:.2f} s)\n", r.measured, r.seconds);
            }
            fmt::print("selftest: {} of {} cases passed, {} failed ({:.1f} s)\n", results.size() - failed, results.size(), failed, seconds);
            for (const auto& r : results)
                if (!r.passed) fmt::print("FAILED: {}\n", r.id());
        }
        exitCode = failed ? 1 : 0;
    });
}

} // namespace vdbdag::cli
