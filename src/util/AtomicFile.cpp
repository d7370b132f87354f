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
#include <mutex>
#include <optional>
#include <set>
#include <ostream>
#include <streambuf>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "src/util/Error.h"
#include "src/util/InputPath.h"
#include "src/util/TemporaryFiles.h"

namespace vdbdag {
namespace {

namespace fs = std::filesystem;

std::string folderOf(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? std::string(".") : parent.string();
}

[[noreturn]] void fail(const std::string& path, const std::string& what, int err) {
    throw Error(path + ": " + what + " (" + std::strerror(err) + ")");
}

std::string describeNonRegular(mode_t mode) {
    if (S_ISLNK(mode)) return "is a symbolic link (give the path it points to)";
    return std::string("is ") + fileKindName(mode);
}

// Clear errors before any temporary exists; also removes what a killed
// earlier write of the same output left behind.
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
    if (::lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) throw Error(path + ": " + describeNonRegular(st.st_mode) + "; vdbdag replaces only regular files");
    removeStaleTemporaries(path);
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

// The outputs that must still be absent when they are written (expectNewFile).
std::mutex newFilesMutex;
std::set<std::string>& newFiles() {
    static std::set<std::string> files;
    return files;
}
std::string keyOf(const std::string& path) { return fs::absolute(path).lexically_normal().string(); }
bool mustBeNew(const std::string& path) {
    std::lock_guard lock(newFilesMutex);
    return newFiles().count(keyOf(path)) > 0;
}
void forgetNewFile(const std::string& path) {
    std::lock_guard lock(newFilesMutex);
    newFiles().erase(keyOf(path));
}

// rename(2) that never replaces: renameat2's RENAME_NOREPLACE, or, on file
// systems without it, link(2) (which fails on an existing name) and unlink.
void renameNoReplace(const std::string& tmp, const std::string& path) {
    auto appeared = [&] {
        removeQuietly(tmp);
        throw Error(path + ": appeared while this command was writing it (another program made it meanwhile); it was not replaced, and nothing "
                           "was written (use -f or --force to replace it)");
    };
    if (::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, path.c_str(), RENAME_NOREPLACE) == 0) return;
    int err = errno;
    if (err == EEXIST) appeared();
    if (err == EINVAL || err == ENOSYS || err == ENOTSUP) {
        if (::link(tmp.c_str(), path.c_str()) == 0) {
            removeQuietly(tmp);
            return;
        }
        err = errno;
        if (err == EEXIST) appeared();
    }
    removeQuietly(tmp);
    fail(path, "cannot create the file", err);
}

void renameOver(const std::string& tmp, const std::string& path) {
    if (mustBeNew(path)) {
        renameNoReplace(tmp, path);
        forgetNewFile(path);  // created: a later write in this process is the command's own
        syncFolder(path);
        return;
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        removeQuietly(tmp);
        fail(path, "cannot replace the file", err);
    }
    syncFolder(path);
}

// Creates a fresh temporary (O_EXCL, a few names tried), registered for
// removal on interrupt before it exists, and returns its fd.
int createTemporary(const std::string& path, std::string& tmp, std::optional<TemporaryGuard>& guard) {
    for (int attempt = 0;; ++attempt) {
        tmp = temporaryNameFor(path);
        guard.emplace(tmp);
        const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) return fd;
        const int err = errno;
        guard.reset();
        if (err != EEXIST || attempt == 8) fail(path, "cannot create a file in " + folderOf(path), err);
    }
}

// Writes all of `bytes` to `fd`; returns 0 or the errno of the failure.
int writeAll(int fd, const uint8_t* data, size_t size) {
    size_t done = 0;
    while (done < size) {
        const ssize_t n = ::write(fd, data + done, size - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        if (n == 0) return ENOSPC;
        done += size_t(n);
    }
    return 0;
}

// A buffered std::streambuf over a file descriptor that remembers the first
// write error (std::ofstream keeps only a failbit, and OpenVDB's writer never
// looks at it).
class FdStreamBuf : public std::streambuf {
public:
    explicit FdStreamBuf(int fd) : fd_(fd), buffer_(1 << 20) { setp(buffer_.data(), buffer_.data() + buffer_.size()); }
    int error() const { return error_; }
    bool flushAll() { return flushBuffer(); }

protected:
    int_type overflow(int_type c) override {
        if (!flushBuffer()) return traits_type::eof();
        if (!traits_type::eq_int_type(c, traits_type::eof())) {
            *pptr() = traits_type::to_char_type(c);
            pbump(1);
        }
        return traits_type::not_eof(c);
    }
    std::streamsize xsputn(const char* s, std::streamsize n) override {
        if (n >= std::streamsize(buffer_.size())) {
            if (!flushBuffer()) return 0;
            if (const int err = writeAll(fd_, reinterpret_cast<const uint8_t*>(s), size_t(n))) {
                error_ = err;
                return 0;
            }
            return n;
        }
        return std::streambuf::xsputn(s, n);
    }
    int sync() override { return flushBuffer() ? 0 : -1; }
    // OpenVDB's archive goes back to fill in each grid's offsets.
    pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override {
        if (!flushBuffer()) return pos_type(off_type(-1));
        const int whence = dir == std::ios_base::beg ? SEEK_SET : dir == std::ios_base::cur ? SEEK_CUR : SEEK_END;
        const off_t at = ::lseek(fd_, off_t(off), whence);
        if (at < 0) {
            error_ = errno;
            return pos_type(off_type(-1));
        }
        return pos_type(off_type(at));
    }
    pos_type seekpos(pos_type pos, std::ios_base::openmode mode) override { return seekoff(off_type(pos), std::ios_base::beg, mode); }

private:
    bool flushBuffer() {
        if (error_) return false;
        const size_t n = size_t(pptr() - pbase());
        if (n) error_ = writeAll(fd_, reinterpret_cast<const uint8_t*>(pbase()), n);
        setp(buffer_.data(), buffer_.data() + buffer_.size());
        return error_ == 0;
    }
    int fd_;
    int error_ = 0;
    std::vector<char> buffer_;
};

// fsync + close the temporary, then rename it over `path`; on failure the
// temporary is removed and Error thrown.
void finishTemporary(const std::string& path, const std::string& tmp, int fd) {
    if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {  // (EINVAL: a file system without fsync)
        const int err = errno;
        ::close(fd);
        removeQuietly(tmp);
        fail(path, "fsync failed", err);
    }
    if (::close(fd) != 0) {
        const int err = errno;
        removeQuietly(tmp);
        fail(path, "close failed", err);
    }
    renameOver(tmp, path);
}

} // namespace

void moveIntoPlace(const std::string& from, const std::string& path) { renameOver(from, path); }

void expectNewFile(const std::string& path, bool isNew) {
    if (!isNew) return forgetNewFile(path);
    std::lock_guard lock(newFilesMutex);
    newFiles().insert(keyOf(path));
}

void writeFileAtomically(const std::string& path, std::span<const uint8_t> bytes) {
    checkDestination(path);
    std::string tmp;
    std::optional<TemporaryGuard> guard;
    const int fd = createTemporary(path, tmp, guard);
    if (const int err = writeAll(fd, bytes.data(), bytes.size())) {
        ::close(fd);
        removeQuietly(tmp);
        fail(path, "write failed", err);
    }
    finishTemporary(path, tmp, fd);
}

void writeStreamAtomically(const std::string& path, const std::function<void(std::ostream& out)>& writeTo) {
    checkDestination(path);
    std::string tmp;
    std::optional<TemporaryGuard> guard;
    const int fd = createTemporary(path, tmp, guard);
    int err = 0;
    FdStreamBuf buffer(fd);
    try {
        std::ostream out(&buffer);
        writeTo(out);
        out.flush();
        buffer.flushAll();
        err = buffer.error();
        if (!err && !out) err = EIO;
    } catch (...) {
        const int writeError = buffer.error();
        ::close(fd);
        removeQuietly(tmp);
        // A writer that gave up on a failed stream has its own message
        // ("writing ... failed"); the path and the system's reason say more.
        if (writeError) fail(path, "write failed", writeError);
        throw;
    }
    if (err) {
        ::close(fd);
        removeQuietly(tmp);
        fail(path, "write failed", err);
    }
    finishTemporary(path, tmp, fd);
}

void writeViaTemporary(const std::string& path, const std::function<void(const std::string& temporaryPath)>& writeTo, const std::string& suffix,
                       bool folder) {
    checkDestination(path);
    const std::string tmp = temporaryNameFor(path, suffix);
    TemporaryGuard guard(tmp, folder);
    try {
        writeTo(tmp);
    } catch (...) {
        std::error_code ec;
        fs::remove_all(tmp, ec);
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
    if (fd < 0) {
        const int err = errno;
        removeQuietly(tmp);
        fail(path, "cannot reopen the written file", err);
    }
    finishTemporary(path, tmp, fd);
}

} // namespace vdbdag
