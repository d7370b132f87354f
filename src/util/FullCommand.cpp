// See FullCommand.h.
#include "src/util/FullCommand.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include "src/util/Error.h"

namespace vdbdag {
namespace {

std::vector<std::string>& savedArguments() {
    static std::vector<std::string> arguments;
    return arguments;
}

} // namespace

void rememberCommandLine(int argc, char** argv) {
    savedArguments().assign(argv, argv + argc);
}

std::string helperCommandPath(const std::string& name) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path program = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return "";
    for (const fs::path& candidate : {program.parent_path() / name, program.parent_path().parent_path() / "lib" / "vdbdag" / name})
        if (fs::exists(candidate, ec) && access(candidate.c_str(), X_OK) == 0) return candidate.string();
    return "";
}

void runHelperCommand(const std::string& name, const std::string& feature) {
    const std::string path = helperCommandPath(name);
    if (path.empty()) throw Error(feature + " needs " + name + ", which is not installed beside this vdbdag");
    if (savedArguments().empty()) throw Error("internal error: " + feature + " needs the command line, which was not saved");
    std::vector<std::string> arguments = savedArguments();
    arguments[0] = path;
    std::vector<char*> argv;
    for (std::string& a : arguments) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::fflush(stdout);
    std::fflush(stderr);
    execv(path.c_str(), argv.data());
    throw Error(feature + ": cannot run " + path + " (" + std::strerror(errno) + ")");
}

} // namespace vdbdag
