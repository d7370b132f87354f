// See GlobalOptions.h.
#include "cli/GlobalOptions.h"

#include <sys/resource.h>

#include <chrono>
#include <memory>
#include <optional>

#include <fmt/core.h>
#include <tbb/global_control.h>

#include "src/util/Progress.h"

namespace vdbdag::cli {
namespace {

struct Globals {
    bool quiet = false, verbose = false;
    std::optional<tbb::global_control> threads;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
};
Globals& globals() {
    static Globals g;
    return g;
}

} // namespace

void addGlobalOptions(CLI::App& app) {
    app.fallthrough();
    app.add_flag_callback("-q,--quiet", [] {
           globals().quiet = true;
           setQuiet(true);
       }, "no progress lines and no notes on stderr (errors and warnings stay)");
    app.add_flag_callback("-v,--verbose", [] { globals().verbose = true; }, "at the end, the command's time and peak memory on stderr");
    app.add_option_function<unsigned>(
           "--threads", [](unsigned n) { globals().threads.emplace(tbb::global_control::max_allowed_parallelism, n); },
           "at most N worker threads (default: one per core); outputs do not depend on it")
        ->check(CLI::Range(1u, 1024u))
        ->type_name("N");
}

void note(const std::string& text) {
    if (!globals().quiet) fmt::print(stderr, "vdbdag: note: {}\n", text);
}

void reportVerbose(const std::string& command) {
    if (!globals().verbose) return;
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - globals().start).count();
    fmt::print(stderr, "vdbdag: {} took {:.2f} s, peak resident memory {:.1f} MB\n", command, seconds, double(usage.ru_maxrss) / 1024.0);
}

} // namespace vdbdag::cli
