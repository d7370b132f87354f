// One zstd frame, the unit of compression at rest: the container's sections
// and each value window (attributes/ValueWindows.h) are one frame each,
// declaring their content size; readers check a frame against the size they
// were told before allocating it.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace vdbdag::format {

// zstd cannot expand data by more than this factor (a 128 KiB RLE block
// costs 4 bytes, a 128 KiB single-match block about 8); a larger claim is a
// corrupt or forged size.
inline constexpr uint64_t kMaxZstdRatio = uint64_t(1) << 16;
inline constexpr uint64_t kMaxZstdSlack = 4096;
// Whether `raw` bytes can come from a `stored`-byte frame (overflow-safe).
bool zstdCanProduce(uint64_t stored, uint64_t raw);

struct ZstdSettings {
    int level = 3;
    bool checksum = false;  // zstd's own content checksum in the frame
    int workers = 0;        // zstd worker threads (0: none)
};

// One frame of `data` with its content size, or empty when zstd does not
// make `data` smaller. A failed allocation is std::bad_alloc (never other
// bytes); other zstd failures are vdbdag::Error.
std::vector<uint8_t> zstdCompressIfSmaller(std::span<const uint8_t> data, const ZstdSettings& settings);

// Bytes of a level-1 frame of `data`, streamed through a small buffer (no
// full-size output): a fast yardstick for choosing between codings.
uint64_t zstdFastSize(std::span<const uint8_t> data);

// Inflates `frame`, which must be exactly one frame declaring `rawSize`
// bytes (the caller has checked zstdCanProduce); throws vdbdag::Error
// starting with `what` otherwise, std::bad_alloc when out of memory.
std::vector<uint8_t> zstdInflateFrame(std::span<const uint8_t> frame, uint64_t rawSize, const std::string& what);

// The first `n` bytes a zstd frame inflates to (fewer when it holds fewer),
// inflating no more than a block or so beyond them: what a report needs to
// read a header inside a large frame. Throws vdbdag::Error starting with
// `what` on corrupt data.
std::vector<uint8_t> zstdFirstBytes(std::span<const uint8_t> frame, size_t n, const std::string& what);

} // namespace vdbdag::format
