// See ScratchFile.h.
#include "src/util/ScratchFile.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "src/util/Error.h"

namespace vdbdag {

namespace {

// Asks the kernel to back the 2 MiB-aligned part of [p, p + size) with
// transparent huge pages: one page fault a 2 MiB page instead of 512.
void adviseHugePages(void* p, size_t size) {
#ifdef MADV_HUGEPAGE
    constexpr uintptr_t kHuge = uintptr_t(2) << 20;
    const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
    const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + size) & ~(kHuge - 1);
    if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // advice: its failure changes nothing
#else
    (void)p, (void)size;
#endif
}

} // namespace

ScratchFile::ScratchFile(const std::string& near, uint64_t keepInMemory) : near_(near), keep_(keepInMemory) {
    if (keep_ == 0) openFile();  // fail early (a folder that cannot be written) when the file is certain
}

ScratchFile::~ScratchFile() {
    if (fd_ >= 0) {
        ::close(fd_);
        ::unlink(path_.c_str());
    }
}

void ScratchFile::openFile() {
    if (fd_ >= 0) return;
    path_ = temporaryNameFor(near_, ".scratch");
    guard_ = std::make_unique<TemporaryGuard>(path_);
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd_ < 0)
        throw Error(path_ + ": cannot create the scratch file (" + std::strerror(errno) + "); choose another folder with --scratch DIR");
}

void ScratchFile::check(uint64_t offset, size_t size, const char* what) const {
    if (offset > size_ || size > size_ - offset)
        throw Error(std::string("internal error: a scratch ") + what + " past the end of " + (path_.empty() ? "the scratch space" : path_));
}

uint64_t ScratchFile::append(const void* data, size_t size) {
    const uint64_t at = size_;
    if (!spilled_ && size <= keep_ - inMemory_) {
        while (uint64_t(chunks_.size()) * kChunk < at + size) {
            chunks_.emplace_back(new uint8_t[kChunk]);  // not zeroed: written before read
            adviseHugePages(chunks_.back().get(), kChunk);
        }
        toMemory(at, data, size);
        inMemory_ += size;
    } else {
        spilled_ = true;
        openFile();
        writeAt(at - inMemory_, data, size);
    }
    size_ += size;
    return at;
}

void ScratchFile::toMemory(uint64_t offset, const void* data, size_t size) {
    const auto* p = static_cast<const uint8_t*>(data);
    while (size) {
        const size_t inChunk = size_t(offset % kChunk), n = std::min(size, kChunk - inChunk);
        std::memcpy(chunks_[size_t(offset / kChunk)].get() + inChunk, p, n);
        offset += n;
        p += n;
        size -= n;
    }
}

void ScratchFile::overwrite(uint64_t offset, const void* data, size_t size) {
    check(offset, size, "overwrite");
    const auto* p = static_cast<const uint8_t*>(data);
    if (offset < inMemory_) {
        const size_t n = size_t(std::min<uint64_t>(size, inMemory_ - offset));
        toMemory(offset, p, n);
        offset += n;
        p += n;
        size -= n;
    }
    if (size) writeAt(offset - inMemory_, p, size);
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

std::span<const uint8_t> ScratchFile::view(uint64_t offset, size_t size, std::vector<uint8_t>& buffer) const {
    check(offset, size, "read");
    if (offset + size <= inMemory_ && offset % kChunk + size <= kChunk)
        return {chunks_[size_t(offset / kChunk)].get() + offset % kChunk, size};
    read(offset, size, buffer);
    return buffer;
}

void ScratchFile::readInto(uint64_t offset, size_t size, void* to) const {
    check(offset, size, "read");
    uint8_t* out = static_cast<uint8_t*>(to);
    while (size && offset < inMemory_) {
        const size_t inChunk = size_t(offset % kChunk), n = size_t(std::min<uint64_t>({size, kChunk - inChunk, inMemory_ - offset}));
        std::memcpy(out, chunks_[size_t(offset / kChunk)].get() + inChunk, n);
        offset += n;
        out += n;
        size -= n;
    }
    for (size_t done = 0; done < size;) {
        const ssize_t n = ::pread(fd_, out + done, size - done, off_t(offset - inMemory_ + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw Error(path_ + ": cannot read the scratch file back (" + std::string(n < 0 ? std::strerror(errno) : "cut short") + ")");
        done += size_t(n);
    }
}

} // namespace vdbdag
