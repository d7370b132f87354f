// Entry point of the `vdbdag` command: OpenVDB volumes <-> SSVDAG files.
// Errors are printed as one line "vdbdag: <message>" with a non-zero exit.
#include <cstdio>
#include <cstring>
#include <exception>

#include <CLI/CLI.hpp>

#include "cli/Commands.h"
#include "cli/RunContext.h"
#include "src/util/Error.h"

int main(int argc, char** argv) {
    vdbdag::cli::installFailureHandlers();
    CLI::App app{"vdbdag: compress OpenVDB volumes into symmetry-aware sparse voxel DAGs (.ssvdag) and back"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "vdbdag 0.1.0");
    int exitCode = 0;
    vdbdag::cli::addEncodeCommand(app, exitCode);
    vdbdag::cli::addDecodeCommand(app, exitCode);
    vdbdag::cli::addInfoCommand(app, exitCode);
    vdbdag::cli::addVerifyCommand(app, exitCode);
    vdbdag::cli::addRenderCommand(app, exitCode);
    vdbdag::cli::addBenchCommand(app, exitCode);
    vdbdag::cli::addDevicesCommand(app, exitCode);
    vdbdag::cli::addExportCommand(app, exitCode);
    vdbdag::cli::addDiffCommand(app, exitCode);
    vdbdag::cli::addSelftestCommand(app, exitCode);
    vdbdag::cli::addImportCommand(app, exitCode);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const vdbdag::Error& e) {
        std::fprintf(stderr, "vdbdag: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "vdbdag: %s\n", vdbdag::cli::outOfMemoryMessage().c_str());
        return 1;
    } catch (const std::exception& e) {
        // TBB reports a thread whose stack could not be mapped this way.
        if (std::strstr(e.what(), "pthread_create has failed") != nullptr)
            std::fprintf(stderr, "vdbdag: %s (no memory for a thread's stack)\n", vdbdag::cli::outOfMemoryMessage().c_str());
        else
            std::fprintf(stderr, "vdbdag: %s\n", e.what());
        return 1;
    }
    return exitCode;
}
