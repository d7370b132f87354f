// Where the decoding of a gzip stream was left, so that the next reader of
// the same stream starts there and not at its first byte.
//
// Why: the volumes of a 4-D .nii.gz (or gzip NRRD) are imported one after
// another (DenseImport, one grid a volume), and the three readers of each
// volume t (the limits check, the size check and the samples) each
// inflated the t volumes before it first: quadratic in the volume count
// (64x64x32 int16 volumes: 50 took 7.1 s, 200 took 112 s). zlib's
// inflateCopy keeps the decoder's whole state (its 32 KB window included,
// and total_out, the bytes decoded so far), so a reader that restores a
// copy and reads the file on from where that copy had consumed it decodes
// exactly the bytes a reader from the start would.
//
// One object per import of such a file, shared by its readers
// (DenseVolume::resume), for one compressed stream (a data file and the
// byte it starts at): a reader of another stream neither saves nor
// restores. It keeps the last kKept positions (an inflate state is about
// 40 KB).
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <zlib.h>

namespace vdbdag::bridge::detail {

class InflateCheckpoints {
public:
    static constexpr size_t kKept = 4;
    InflateCheckpoints() = default;
    InflateCheckpoints(const InflateCheckpoints&) = delete;
    InflateCheckpoints& operator=(const InflateCheckpoints&) = delete;

    // Keeps a copy of `z`, a decoder of `stream` (its data file and first
    // byte, as the reader names them) that has decoded z.total_out bytes
    // and consumed the file up to byte `filePosition` (what it read less its
    // unused input). Nothing is kept for a position at the stream's start or
    // already kept, for another stream than the first one saved, or when
    // zlib cannot make the copy (out of memory).
    void save(const std::string& stream, const z_stream& z, uint64_t filePosition);

    struct Resumed {
        uint64_t decoded = 0, filePosition = 0;
    };
    // The kept position of `stream` furthest in but at most `want` decoded
    // bytes in: `z` (a decoder begun with inflateInit2(&z, 15 + 32)) becomes
    // a copy of its state, with no input and no output buffer; the caller
    // reads the file on from `filePosition`. None: nullopt, `z` as it was.
    // Throws vdbdag::Error when zlib can neither copy nor begin a decoder.
    std::optional<Resumed> restore(const std::string& stream, uint64_t want, z_stream& z);

    // Decoded bytes the restores so far saved their readers (a statistic).
    uint64_t resumedBytes() const;

private:
    // zlib's state points back at its z_stream (inflate refuses a stream
    // whose state belongs to another address): a checkpoint never moves,
    // and a copy is made into the stream that will use it.
    struct Checkpoint {
        uint64_t filePosition = 0;
        z_stream z{};  // inflateCopy's
        ~Checkpoint() { inflateEnd(&z); }
    };
    mutable std::mutex mutex_;
    std::string stream_;  // the stream saved first
    std::deque<std::unique_ptr<Checkpoint>> kept_;  // the newest last
    uint64_t resumed_ = 0;
};

} // namespace vdbdag::bridge::detail
