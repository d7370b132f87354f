// See ScratchFile.h.
#include "src/util/ScratchFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "src/util/Error.h"

namespace vdbdag {

ScratchFile::ScratchFile(const std::string& near) {
    path_ = temporaryNameFor(near, ".scratch");
    guard_ = std::make_unique<TemporaryGuard>(path_);
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd_ < 0)
        throw Error(path_ + ": cannot create the scratch file (" + std::strerror(errno) + "); choose another folder with --scratch DIR");
}

ScratchFile::~ScratchFile() {
    if (fd_ >= 0) ::close(fd_);
    ::unlink(path_.c_str());
}

uint64_t ScratchFile::append(const void* data, size_t size) {
    const uint64_t at = size_;
    writeAt(at, data, size);
    size_ += size;
    return at;
}

void ScratchFile::overwrite(uint64_t offset, const void* data, size_t size) {
    if (offset > size_ || size > size_ - offset) throw Error("internal error: a scratch overwrite past the end of " + path_);
    writeAt(offset, data, size);
}

void ScratchFile::writeAt(uint64_t at, const void* data, size_t size) {
    const auto* p = static_cast<const uint8_t*>(data);
    for (size_t done = 0; done < size;) {
        const ssize_t n = ::pwrite(fd_, p + done, size - done, off_t(at + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0)
            throw Error(path_ + ": cannot write the scratch file (" + std::string(n < 0 ? std::strerror(errno) : "nothing written") +
                        "); free some space or choose another folder with --scratch DIR");
        done += size_t(n);
    }
}

void ScratchFile::read(uint64_t offset, size_t size, std::vector<uint8_t>& out) const {
    out.resize(size);
    readInto(offset, size, out.data());
}

void ScratchFile::readInto(uint64_t offset, size_t size, void* to) const {
    if (offset > size_ || size > size_ - offset) throw Error("internal error: a scratch read past the end of " + path_);
    uint8_t* const out = static_cast<uint8_t*>(to);
    for (size_t done = 0; done < size;) {
        const ssize_t n = ::pread(fd_, out + done, size - done, off_t(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw Error(path_ + ": cannot read the scratch file back (" + std::string(n < 0 ? std::strerror(errno) : "cut short") + ")");
        done += size_t(n);
    }
}

} // namespace vdbdag
