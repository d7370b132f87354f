// Runs a shell command (usually the `vdbdag` binary) for the CLI tests and
// captures its exit code, stdout and stderr.
#pragma once
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/unit/BuildPaths.h"

namespace vdbdag::testing {

struct CommandResult {
    int exitCode;
    std::string out, err;
};

// `command` as given to the shell; stderr is captured through a temporary file.
inline CommandResult runShell(const std::string& command) {
    static std::atomic<int> counter{0};
    namespace fs = std::filesystem;
    const fs::path errFile = fs::temp_directory_path() / ("vdbdag_test_err_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
    CommandResult r{};
    FILE* pipe = popen((command + " 2>" + errFile.string()).c_str(), "r");
    std::array<char, 4096> buffer{};
    size_t n;
    while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.out.append(buffer.data(), n);
    const int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream in(errFile);
    r.err.assign(std::istreambuf_iterator<char>(in), {});
    fs::remove(errFile);
    return r;
}

// A folder of its own for a test file's outputs ("vdbdag_TAG_PID" in the
// temporary directory), emptied once per process: a finished process with
// the same PID may have left one behind.
inline std::filesystem::path testFolder(const std::string& tag) {
    namespace fs = std::filesystem;
    const fs::path d = fs::temp_directory_path() / ("vdbdag_" + tag + "_" + std::to_string(getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

// `vdbdag ARGS`; `envPrefix`: e.g. "env VAR=value " before the binary.
inline CommandResult runCli(const std::string& args, const std::string& envPrefix = "") {
    return runShell(envPrefix + std::string(VDBDAG_BINARY) + " " + args);
}

} // namespace vdbdag::testing
