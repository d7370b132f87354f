// Scratch space for data an out-of-core pass writes once and reads back by
// pieces (the cube-by-cube reader keeps each leaf's decoded bricks there,
// the value windows their coded bytes). The first `keepInMemory` bytes stay
// in memory; the rest goes to a file created beside `near` as
// ".NAME.tmp.PID.RANDOM.scratch" when first needed, removed when the object
// dies, and on Ctrl-C, SIGTERM, a crash or running out of memory
// (TemporaryFiles.h). Every write is checked: a full disk is an Error naming
// the scratch file, never a short read later.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "src/util/TemporaryFiles.h"

namespace vdbdag {

class ScratchFile {
public:
    // `near`: a path in the folder to use (the file need not exist).
    explicit ScratchFile(const std::string& near, uint64_t keepInMemory = 0);
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
    // The bytes themselves where memory holds them in one piece (no copy),
    // else read into `buffer`.
    std::span<const uint8_t> view(uint64_t offset, size_t size, std::vector<uint8_t>& buffer) const;
    uint64_t size() const { return size_; }
    // The file's path (empty while every byte is in memory).
    const std::string& path() const { return path_; }

private:
    static constexpr size_t kChunk = size_t(16) << 20;  // memory is kept in chunks: no copy as it grows
    void check(uint64_t offset, size_t size, const char* what) const;
    void openFile();
    void writeAt(uint64_t offset, const void* data, size_t size);  // file offsets
    void toMemory(uint64_t offset, const void* data, size_t size);
    std::string near_, path_;
    int fd_ = -1;
    uint64_t size_ = 0;
    uint64_t keep_ = 0;       // bytes allowed in memory
    uint64_t inMemory_ = 0;   // bytes [0, inMemory_) are in memory, the rest in the file
    bool spilled_ = false;    // once data went to the file, all later data does
    std::vector<std::unique_ptr<uint8_t[]>> chunks_;
    std::unique_ptr<TemporaryGuard> guard_;
};

} // namespace vdbdag
