// See OutputPath.h.
#include "src/util/OutputPath.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <sys/stat.h>

#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/InputPath.h"

namespace vdbdag {

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

void checkOutputPath(const std::string& output, const std::vector<std::string>& inputs, const OutputRules& rules) {
    // The same file as an input, through any link or path spelling.
    struct stat target{};
    if (::stat(output.c_str(), &target) == 0) {
        for (const std::string& input : inputs) {
            struct stat in{};
            if (::stat(input.c_str(), &in) == 0 && in.st_dev == target.st_dev && in.st_ino == target.st_ino)
                throw Error(output + ": is " + (input == output ? std::string("the input") : "the same file as the input " + input) + "; " +
                            rules.command + " never writes over what it reads");
        }
    }
    const std::string ext = lowerExtension(output);
    if (!rules.extensions.empty() && std::find(rules.extensions.begin(), rules.extensions.end(), ext) == rules.extensions.end()) {
        std::string list;
        for (size_t i = 0; i < rules.extensions.size(); ++i)
            list += (i == 0 ? "" : i + 1 == rules.extensions.size() ? " or " : ", ") + rules.extensions[i];
        throw Error(output + ": " + rules.command + " writes " + list + " files; the extension names the format" +
                    (ext.empty() ? " and this name has none" : ", and '" + ext + "' is not one it writes"));
    }
    struct stat out{};
    if (::lstat(output.c_str(), &out) != 0) {
        if (errno != ENOENT && errno != ENOTDIR) throw Error(output + ": cannot be checked (" + std::strerror(errno) + ")");
        // Its folder, before any work (and any scratch file beside it).
        const std::string dir = std::filesystem::path(output).parent_path().empty() ? "." : std::filesystem::path(output).parent_path().string();
        struct stat folder{};
        if (::stat(dir.c_str(), &folder) != 0 && (errno == ENOENT || errno == ENOTDIR)) throw Error(output + ": the folder " + dir + " does not exist");
        // Absent now: it must still be absent when written (two commands
        // racing to create it: the later one fails, nothing is replaced).
        expectNewFile(output, !rules.force);
        return;  // the rest of the folder's checks are the atomic writer's
    }
    if (S_ISLNK(out.st_mode)) throw Error(output + ": is a symbolic link; not writing through it (give the path it points to)");
    if (S_ISDIR(out.st_mode)) throw Error(output + ": is a directory");
    if (!S_ISREG(out.st_mode)) throw Error(output + ": is " + fileKindName(out.st_mode) + "; " + rules.command + " writes only regular files");
    if ((out.st_mode & 0222) == 0) throw Error(output + ": exists and is read-only; not replacing it");
    if (!rules.force) throw Error(output + ": already exists (use -f or --force to replace it)");
    expectNewFile(output, false);  // replacing it is what the user asked for
}

} // namespace vdbdag
