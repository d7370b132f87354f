// Atomic output: temporary file beside the destination, fsync, rename.
#include "src/util/AtomicFile.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>

#include <fcntl.h>
#include <unistd.h>

#include "src/util/Error.h"

namespace vdbdag {
namespace {

std::string temporaryNameFor(const std::string& path) {
    const std::filesystem::path p(path);
    std::random_device rd;
    const std::string name = "." + p.filename().string() + ".tmp." + std::to_string(getpid()) + "." + std::to_string(rd());
    return (p.parent_path() / name).string();
}

void checkDestination(const std::string& path) {
    const std::filesystem::path p(path);
    if (p.filename().empty()) throw Error(path + ": not a file name");
    const std::filesystem::path dir = p.parent_path().empty() ? std::filesystem::path(".") : p.parent_path();
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) throw Error(path + ": the folder " + dir.string() + " does not exist");
    if (std::filesystem::is_directory(p, ec)) throw Error(path + ": is a directory");
}

} // namespace

void writeFileAtomically(const std::string& path, std::span<const uint8_t> bytes) {
    checkDestination(path);
    const std::string tmp = temporaryNameFor(path);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) throw Error(path + ": cannot write (" + std::strerror(errno) + ")");
    auto failAndClean = [&](const char* what) {
        const int err = errno;
        ::close(fd);
        ::unlink(tmp.c_str());
        throw Error(path + ": " + what + " (" + std::strerror(err) + ")");
    };
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            failAndClean("write failed");
        }
        done += size_t(n);
    }
    if (::fsync(fd) != 0) failAndClean("fsync failed");
    if (::close(fd) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        throw Error(path + ": close failed (" + std::strerror(err) + ")");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        throw Error(path + ": rename failed (" + std::strerror(err) + ")");
    }
}

void writeViaTemporary(const std::string& path, const std::function<void(const std::string& temporaryPath)>& writeTo) {
    checkDestination(path);
    const std::string tmp = temporaryNameFor(path);
    try {
        writeTo(tmp);
    } catch (...) {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw;
    }
    std::error_code ec;
    if (!std::filesystem::exists(tmp, ec)) throw Error(path + ": the writer produced no file");
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        std::filesystem::remove(tmp, ec);
        throw Error(path + ": rename failed (" + std::strerror(err) + ")");
    }
}

} // namespace vdbdag
