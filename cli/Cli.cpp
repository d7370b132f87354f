// The `vdbdag` command line as a function, for the plain binary (main.cpp)
// and the MPI one (distributed/main.cpp). Errors are printed as one line
// "vdbdag: <message>" with a non-zero exit; mistakes in the command line
// itself as one line with exit status 2 (UsageErrors.h).
#include "cli/Cli.h"

#include <cstdio>
#include <cstring>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <exception>

#include <CLI/CLI.hpp>

#include "cli/Commands.h"
#include "cli/GlobalOptions.h"
#include "cli/RunContext.h"
#include "cli/UsageErrors.h"
#include "cli/JsonReport.h"
#include "src/util/Error.h"
#include "src/util/FullCommand.h"

namespace vdbdag::cli {

int runVdbdag(int argc, char** argv, pipeline::CubeTeam& team) {
    rememberCommandLine(argc, argv);  // for a call that needs vdbdag-full (src/util/FullCommand.h)
    setCubeTeam(team);
#ifdef __GLIBC__
    // Blocks of 4 MiB and more (value windows, cubes, DAG levels) from and
    // back to the system, never kept in the heap: glibc otherwise raises
    // its threshold as such blocks are freed and keeps them, which cost an
    // encode in bounded memory a tenth more resident memory, and no speed.
    mallopt(M_MMAP_THRESHOLD, 4 << 20);
    // The smaller blocks freed at the top of a heap stay there up to 64 MiB
    // (glibc gives back all but 128 KiB): an encode frees and takes them by
    // the thousand (pieces of cubes, window layouts, DAG facts), and every
    // page given back is faulted in again. The d=1024 sphere's encode took
    // 179k page faults and 4.31 s, now 156k and 3.91 s (medians of 5,
    // alternated; 303 -> 305 MB peak; 12 % off at --memory-limit 256M);
    // keeping blocks of 4 MiB and more as well saved 5 % more for 10 % more
    // memory.
    mallopt(M_TRIM_THRESHOLD, 64 << 20);
#endif
    // Under mpirun every process runs the command line; only `encode` is
    // shared among them, anything else runs on process 0 alone.
    if (!team.isRoot() && (argc < 2 || std::strcmp(argv[1], "encode") != 0)) return 0;
    installFailureHandlers();
    CLI::App app{"vdbdag: compress OpenVDB volumes into symmetry-aware sparse voxel DAGs (.ssvdag) and back", "vdbdag"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("vdbdag ") + kToolVersion);
    // Every option's --help shows its default value.
    app.option_defaults()->always_capture_default();
    addGlobalOptions(app);
    int exitCode = 0;
    addEncodeCommand(app, exitCode);
    addDecodeCommand(app, exitCode);
    addInfoCommand(app, exitCode);
    addVerifyCommand(app, exitCode);
    addRenderCommand(app, exitCode);
    addBenchCommand(app, exitCode);
    addDevicesCommand(app, exitCode);
    addExportCommand(app, exitCode);
    addDiffCommand(app, exitCode);
    addSelftestCommand(app, exitCode);
    addImportCommand(app, exitCode);
    // An example per command, under its --help.
    const std::pair<const char*, const char*> examples[] = {
        {"encode", "vdbdag encode smoke.vdb -o smoke.ssvdag --memory-limit 4G\n  vdbdag encode ct_series/ -o ct.ssvdag --background-below -900"},
        {"decode", "vdbdag decode smoke.ssvdag -o smoke.vdb\n  vdbdag decode ct.ssvdag -o ct.nii.gz"},
        {"info", "vdbdag info smoke.ssvdag --json\n  vdbdag info ct_series/"},
        {"verify", "vdbdag verify smoke.vdb\n  vdbdag verify smoke.vdb --encoded smoke.ssvdag"},
        {"render", "vdbdag render smoke.ssvdag -o smoke.png --shadows\n  vdbdag render scan.ssvdag -o scan.exr --up z --view front"},
        {"devices", "vdbdag devices --json"},
        {"export", "vdbdag export smoke.ssvdag -o smoke.vtu\n  vdbdag export smoke.ssvdag -o box.vti --bbox 0,0,0,63,63,63"},
        {"diff", "vdbdag diff smoke.vdb lossy.ssvdag -o diff.vtu"},
        {"import", "vdbdag import ct_512x512x300_int16le.raw -o ct.vdb"},
        {"bench", "vdbdag bench smoke.vdb -o report/ --sweep quick"},
        {"selftest", "vdbdag selftest --list"},
    };
    for (const auto& entry : examples) {
        const std::string name(entry.first);
        for (CLI::App* sub : app.get_subcommands([&](CLI::App* s) { return s->get_name() == name; })) sub->footer(std::string("Example:\n  ") + entry.second);
    }
    // The environment variables anything of ours reads, on the help of the
    // commands they affect and of vdbdag itself (none changes a file's bytes).
    const std::string environment =
        "Environment: VDBDAG_VULKAN_VALIDATION=1 turns on the Khronos validation layer (its messages on stderr); VK_ICD_FILENAMES or "
        "VK_DRIVER_FILES choose the Vulkan drivers the loader sees (e.g. lavapipe's lvp_icd.x86_64.json).";
    for (CLI::App* sub : app.get_subcommands([](CLI::App* s) { return s->get_name() == "render" || s->get_name() == "devices"; }))
        sub->footer(sub->get_footer() + "\n" + environment);
    app.footer("Exit status: 0 done (diff: the same), 1 failed (diff: they differ), 2 a mistake in the command line (diff: failed).\n"
               "vdbdag help COMMAND, or vdbdag COMMAND --help, describes a command.\n" + environment);
    if (const std::optional<int> helped = answerHelpCommand(app, argc, argv)) return *helped;
    try {
        app.parse(argc, argv);
        for (const CLI::App* sub : app.get_subcommands()) reportVerbose(sub->get_name());
    } catch (const CLI::ParseError& e) {
        return answerParseError(app, e, argc, argv);
    } catch (const Error& e) {
        std::fprintf(stderr, "vdbdag: %s\n", e.what());
        return failureExitCode();
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "vdbdag: %s\n", outOfMemoryMessage().c_str());
        return failureExitCode();
    } catch (const std::exception& e) {
        // TBB reports a thread whose stack could not be mapped this way.
        if (std::strstr(e.what(), "pthread_create has failed") != nullptr)
            std::fprintf(stderr, "vdbdag: %s (no memory for a thread's stack)\n", outOfMemoryMessage().c_str());
        else
            std::fprintf(stderr, "vdbdag: %s\n", e.what());
        return failureExitCode();
    }
    return exitCode;
}

} // namespace vdbdag::cli
