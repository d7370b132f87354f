// See InputPath.h.
#include "src/util/InputPath.h"

#include <cerrno>
#include <cstring>

#include <sys/stat.h>

#include "src/util/Error.h"

namespace vdbdag {

const char* fileKindName(unsigned mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISLNK(mode)) return "a symbolic link";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISSOCK(mode)) return "a socket";
    if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
    return "a special file";
}

void checkInputFile(const std::string& path, const std::string& what) {
    struct stat st{};
    if (::stat(path.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) throw Error(path + ": no such file");
        throw Error(path + ": cannot be read (" + std::strerror(errno) + ")");
    }
    if (S_ISREG(st.st_mode)) return;
    throw Error(path + ": is " + fileKindName(st.st_mode) + ", not " + what);
}

} // namespace vdbdag
