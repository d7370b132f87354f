// See InputPath.h.
#include "src/util/InputPath.h"

#include <cerrno>
#include <cstring>

#include <sys/stat.h>

#include "src/util/Error.h"

namespace vdbdag {

void checkInputFile(const std::string& path, const std::string& what) {
    struct stat st{};
    if (::stat(path.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) throw Error(path + ": no such file");
        throw Error(path + ": cannot be read (" + std::strerror(errno) + ")");
    }
    if (S_ISREG(st.st_mode)) return;
    const char* kind = S_ISDIR(st.st_mode) ? "a directory" : S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISSOCK(st.st_mode) ? "a socket"
                     : (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) ? "a device" : "not a regular file";
    throw Error(path + ": is " + kind + ", not " + what);
}

} // namespace vdbdag
