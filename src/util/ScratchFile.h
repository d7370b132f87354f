// A scratch file for data an out-of-core pass writes once and reads back
// by pieces (the cube-by-cube reader keeps each leaf's decoded bricks
// there). Created beside `near` as ".NAME.tmp.PID.RANDOM.scratch", removed
// when the object dies, and on Ctrl-C, SIGTERM, a crash or running out of
// memory (TemporaryFiles.h). Every write is checked: a full disk is an
// Error naming the scratch file, never a short read later.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "src/util/TemporaryFiles.h"

namespace vdbdag {

class ScratchFile {
public:
    // `near`: a path in the folder to use (the file need not exist).
    explicit ScratchFile(const std::string& near);
    ~ScratchFile();
    ScratchFile(const ScratchFile&) = delete;
    ScratchFile& operator=(const ScratchFile&) = delete;

    // Appends `size` bytes; returns their offset.
    uint64_t append(const void* data, size_t size);
    // Replaces bytes already written (`offset + size` <= size()).
    void overwrite(uint64_t offset, const void* data, size_t size);
    // Reads `size` bytes at `offset` into `out` (resized).
    void read(uint64_t offset, size_t size, std::vector<uint8_t>& out) const;
    // The same into `size` bytes at `to`.
    void readInto(uint64_t offset, size_t size, void* to) const;
    uint64_t size() const { return size_; }
    const std::string& path() const { return path_; }

private:
    void writeAt(uint64_t offset, const void* data, size_t size);
    std::string path_;
    int fd_ = -1;
    uint64_t size_ = 0;
    std::unique_ptr<TemporaryGuard> guard_;
};

} // namespace vdbdag
