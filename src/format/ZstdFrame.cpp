// See ZstdFrame.h.
#include "src/format/ZstdFrame.h"

#include <limits>
#include <memory>
#include <new>

#include <zstd.h>
#include <zstd_errors.h>

#include "src/util/Error.h"

namespace vdbdag::format {
namespace {

struct CCtxDeleter {
    void operator()(ZSTD_CCtx* c) const { ZSTD_freeCCtx(c); }
};
using CCtx = std::unique_ptr<ZSTD_CCtx, CCtxDeleter>;

CCtx makeContext() {
    CCtx cctx(ZSTD_createCCtx());
    if (!cctx) throw std::bad_alloc();
    return cctx;
}

// zstd reports a failed allocation as an error code; it is the same out of
// memory as a failed `new`, and the command line says so in one line.
void check(size_t r) {
    if (!ZSTD_isError(r)) return;
    if (ZSTD_getErrorCode(r) == ZSTD_error_memory_allocation) throw std::bad_alloc();
    throw Error(std::string("zstd compression failed: ") + ZSTD_getErrorName(r));
}

std::string num(uint64_t v) { return std::to_string(v); }

} // namespace

bool zstdCanProduce(uint64_t stored, uint64_t raw) {
    return stored <= (std::numeric_limits<uint64_t>::max() - kMaxZstdSlack) / kMaxZstdRatio && raw <= stored * kMaxZstdRatio + kMaxZstdSlack;
}

std::vector<uint8_t> zstdCompressIfSmaller(std::span<const uint8_t> data, const ZstdSettings& settings) {
    if (data.size() < 2) return {};
    CCtx cctx = makeContext();
    check(ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_compressionLevel, settings.level));
    check(ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_contentSizeFlag, 1));  // readers require the frame content size
    if (settings.checksum) check(ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_checksumFlag, 1));
    if (settings.workers) ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_nbWorkers, settings.workers);  // fails harmlessly if libzstd lacks threads
    // A destination one byte smaller than the input: if zstd cannot fit there
    // it does not shrink the data, found without a full-size bound.
    std::vector<uint8_t> out(data.size() - 1);
    const size_t n = ZSTD_compress2(cctx.get(), out.data(), out.size(), data.data(), data.size());
    if (ZSTD_isError(n)) {
        if (ZSTD_getErrorCode(n) == ZSTD_error_dstSize_tooSmall) return {};
        check(n);
    }
    out.resize(n);
    out.shrink_to_fit();  // the frame alone: its capacity was the input's size
    return out;
}

uint64_t zstdFastSize(std::span<const uint8_t> data) {
    CCtx cctx = makeContext();
    check(ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_compressionLevel, 1));
    std::vector<uint8_t> buffer(size_t(1) << 18);
    ZSTD_inBuffer in{data.data(), data.size(), 0};
    uint64_t total = 0;
    for (;;) {
        ZSTD_outBuffer out{buffer.data(), buffer.size(), 0};
        const size_t left = ZSTD_compressStream2(cctx.get(), &out, &in, ZSTD_e_end);
        check(left);
        total += out.pos;
        if (left == 0) return total;
    }
}

std::vector<uint8_t> zstdInflateFrame(std::span<const uint8_t> stored, uint64_t rawSize, const std::string& what) {
    const size_t frameBytes = ZSTD_findFrameCompressedSize(stored.data(), stored.size());
    if (ZSTD_isError(frameBytes)) throw Error(what + ": corrupted zstd frame (" + ZSTD_getErrorName(frameBytes) + ")");
    if (frameBytes != stored.size())
        throw Error(what + ": the zstd frame takes " + num(frameBytes) + " of the section's " + num(stored.size()) + " bytes, the file is corrupted");
    const unsigned long long declared = ZSTD_getFrameContentSize(stored.data(), stored.size());
    if (declared == ZSTD_CONTENTSIZE_ERROR || declared == ZSTD_CONTENTSIZE_UNKNOWN)
        throw Error(what + ": the zstd frame does not declare its size, the file is corrupted");
    if (declared != rawSize)
        throw Error(what + ": the zstd frame declares " + num(declared) + " bytes but the table " + num(rawSize) + ", the file is corrupted");
    std::vector<uint8_t> data(rawSize);
    const size_t n = ZSTD_decompress(data.data(), data.size(), stored.data(), stored.size());
    if (ZSTD_isError(n)) {
        if (ZSTD_getErrorCode(n) == ZSTD_error_memory_allocation) throw std::bad_alloc();
        throw Error(what + ": corrupted zstd data (" + ZSTD_getErrorName(n) + ")");
    }
    if (n != rawSize) throw Error(what + ": zstd restored " + num(n) + " bytes instead of " + num(rawSize) + ", the file is corrupted");
    return data;
}

std::vector<uint8_t> zstdFirstBytes(std::span<const uint8_t> frame, size_t n, const std::string& what) {
    std::unique_ptr<ZSTD_DStream, size_t (*)(ZSTD_DStream*)> stream(ZSTD_createDStream(), ZSTD_freeDStream);
    if (!stream) throw std::bad_alloc();
    std::vector<uint8_t> out(n);
    ZSTD_inBuffer in{frame.data(), frame.size(), 0};
    ZSTD_outBuffer o{out.data(), out.size(), 0};
    while (o.pos < o.size && in.pos < in.size) {
        const size_t r = ZSTD_decompressStream(stream.get(), &o, &in);
        if (ZSTD_isError(r)) throw Error(what + ": corrupted zstd data (" + ZSTD_getErrorName(r) + ")");
        if (r == 0) break;  // the frame ended
    }
    out.resize(o.pos);
    return out;
}

} // namespace vdbdag::format
