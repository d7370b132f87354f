// Atomic output: a temporary file beside the destination
// (".NAME.tmp.PID.RANDOM", so it is hidden, on the same file system and
// unique per process and call), written, fsync'ed, closed and renamed over
// the destination; the folder is fsync'ed afterwards so the rename itself is
// durable. Any failure removes the temporary and throws vdbdag::Error naming
// the destination and the system's reason.
#include "src/util/AtomicFile.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "src/util/Error.h"

namespace vdbdag {
namespace {

namespace fs = std::filesystem;

std::string folderOf(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? std::string(".") : parent.string();
}

std::string temporaryNameFor(const std::string& path) {
    static thread_local std::mt19937_64 rng{std::random_device{}() ^ (uint64_t(getpid()) << 32)};
    const fs::path p(path);
    std::string name = ".";  // built by appending: GCC 12 warns (-Wrestrict) about "." + string
    name += p.filename().string();
    name += ".tmp.";
    name += std::to_string(getpid());
    name += '.';
    name += std::to_string(rng() & 0xFFFFFFFFFFFFull);
    return (p.parent_path() / name).string();
}

[[noreturn]] void fail(const std::string& path, const std::string& what, int err) {
    throw Error(path + ": " + what + " (" + std::strerror(err) + ")");
}

// Clear errors before any temporary exists.
void checkDestination(const std::string& path) {
    const fs::path p(path);
    if (path.empty() || p.filename().empty() || p.filename() == "." || p.filename() == "..") throw Error(path + ": not a file name");
    const std::string dir = folderOf(path);
    struct stat st{};
    if (::stat(dir.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) throw Error(path + ": the folder " + dir + " does not exist");
        fail(path, "cannot access the folder " + dir, errno);
    }
    if (!S_ISDIR(st.st_mode)) throw Error(path + ": " + dir + " is not a folder");
    if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) throw Error(path + ": is a directory");
}

void removeQuietly(const std::string& tmp) {
    const int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
}

// Best effort: makes the rename durable. Not every file system supports it.
void syncFolder(const std::string& path) {
    const int fd = ::open(folderOf(path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    ::fsync(fd);
    ::close(fd);
}

void renameOver(const std::string& tmp, const std::string& path) {
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        removeQuietly(tmp);
        fail(path, "cannot replace the file", err);
    }
    syncFolder(path);
}

// Creates a fresh temporary (O_EXCL, a few names tried) and returns its fd.
int createTemporary(const std::string& path, std::string& tmp) {
    for (int attempt = 0;; ++attempt) {
        tmp = temporaryNameFor(path);
        const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) return fd;
        if (errno != EEXIST || attempt == 8) fail(path, "cannot create a file in " + folderOf(path), errno);
    }
}

} // namespace

void writeFileAtomically(const std::string& path, std::span<const uint8_t> bytes) {
    checkDestination(path);
    std::string tmp;
    const int fd = createTemporary(path, tmp);
    auto failAndClean = [&](const char* what, int err) {
        ::close(fd);
        removeQuietly(tmp);
        fail(path, what, err);
    };
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            failAndClean("write failed", errno);
        }
        if (n == 0) failAndClean("write failed", ENOSPC);
        done += size_t(n);
    }
    if (::fsync(fd) != 0) failAndClean("fsync failed", errno);
    if (::close(fd) != 0) {
        const int err = errno;
        removeQuietly(tmp);
        fail(path, "close failed", err);
    }
    renameOver(tmp, path);
}

void writeViaTemporary(const std::string& path, const std::function<void(const std::string& temporaryPath)>& writeTo) {
    checkDestination(path);
    const std::string tmp = temporaryNameFor(path);
    try {
        writeTo(tmp);
    } catch (...) {
        removeQuietly(tmp);
        throw;
    }
    struct stat st{};
    if (::lstat(tmp.c_str(), &st) != 0) throw Error(path + ": the writer produced no file");
    if (!S_ISREG(st.st_mode)) {
        std::error_code ec;
        fs::remove_all(tmp, ec);
        throw Error(path + ": the writer produced something other than a regular file");
    }
    // The writer closed its file; flush it to disk before the rename.
    const int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0 || ::fsync(fd) != 0) {
        const int err = errno;
        if (fd >= 0) ::close(fd);
        removeQuietly(tmp);
        fail(path, "fsync failed", err);
    }
    ::close(fd);
    renameOver(tmp, path);
}

} // namespace vdbdag
