// Where the decoding of a gzip stream was left, so that the next reader of
// the same stream starts there and not at its first byte.
//
// Why: the volumes of a 4-D .nii.gz (or gzip NRRD) are imported one after
// another (DenseImport, one grid a volume), and each reader of volume t
// inflated the t volumes before it first, twice (the size check and the
// samples): quadratic in the volume count. 200 volumes of 64x64x32 took
// 112 s against 8.2 s for 50. zlib's inflateCopy keeps the decoder's whole
// state (its 32 KB window included), so a reader that restores a copy taken
// at decoded byte n and reads the file on from where that copy had consumed
// it decodes exactly the bytes a reader from the start would.
//
// One object per import of such a file, shared by its readers
// (DenseVolume::resume); never shared across files or imports, so a file
// changed between two imports cannot be read from a stale state. It keeps
// the last kKept positions (an inflate state is about 40 KB).
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>

#include <zlib.h>

namespace vdbdag::bridge::detail {

class InflateCheckpoints {
public:
    static constexpr size_t kKept = 4;
    InflateCheckpoints() = default;
    ~InflateCheckpoints();
    InflateCheckpoints(const InflateCheckpoints&) = delete;
    InflateCheckpoints& operator=(const InflateCheckpoints&) = delete;

    // Keeps a copy of `z`, which has decoded `decoded` bytes of the stream
    // and consumed the file up to byte `filePosition` (what it read less its
    // unused input). A position already kept, or a copy zlib cannot make
    // (out of memory), keeps nothing.
    void save(uint64_t decoded, const z_stream& z, uint64_t filePosition);

    struct Resumed {
        uint64_t decoded = 0, filePosition = 0;
    };
    // The kept position furthest into the stream but at most `want` decoded
    // bytes in: `z` (an initialised inflate stream) becomes a copy of its
    // state, with no input and no output buffer; the caller reads the file
    // on from `filePosition`. Nothing kept so far in: nullopt, `z` as it was.
    std::optional<Resumed> restore(uint64_t want, z_stream& z);
    // Decoded bytes the restores so far saved their readers (a statistic).
    uint64_t resumedBytes() const { return resumed_; }

private:
    // zlib's state points back at its z_stream (inflate refuses a stream
    // whose state belongs to another address): a checkpoint never moves,
    // and a copy is made into the stream that will use it.
    struct Checkpoint {
        uint64_t decoded = 0, filePosition = 0;
        z_stream z{};  // inflateCopy's, ended by the destructor
    };
    std::mutex mutex_;
    std::deque<std::unique_ptr<Checkpoint>> kept_;  // the newest last
    uint64_t resumed_ = 0;
};

} // namespace vdbdag::bridge::detail
