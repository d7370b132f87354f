// See InflateCheckpoints.h.
#include "vdb_bridge/detail/InflateCheckpoints.h"

#include "src/util/Error.h"

namespace vdbdag::bridge::detail {

void InflateCheckpoints::save(const std::string& stream, const z_stream& z, uint64_t filePosition) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (z.total_out == 0) return;
    if (stream_.empty()) stream_ = stream;
    if (stream != stream_) return;
    for (const auto& c : kept_)
        if (c->z.total_out == z.total_out) return;
    auto c = std::make_unique<Checkpoint>();
    c->filePosition = filePosition;
    if (inflateCopy(&c->z, const_cast<z_stream*>(&z)) != Z_OK) {
        c->z = z_stream{};  // nothing to end
        return;
    }
    c->z.next_in = nullptr;  // the reader's buffers, which it keeps
    c->z.avail_in = 0;
    c->z.next_out = nullptr;
    c->z.avail_out = 0;
    if (kept_.size() == kKept) kept_.pop_front();
    kept_.push_back(std::move(c));
}

std::optional<InflateCheckpoints::Resumed> InflateCheckpoints::restore(const std::string& stream, uint64_t want, z_stream& z) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (stream != stream_) return std::nullopt;
    const Checkpoint* best = nullptr;
    for (const auto& c : kept_)
        if (c->z.total_out <= want && (!best || c->z.total_out > best->z.total_out)) best = c.get();
    if (!best) return std::nullopt;
    // The fresh decoder goes; its copy of the checkpoint takes its place
    // (or, should zlib fail to copy, a fresh decoder again).
    inflateEnd(&z);
    z = z_stream{};
    if (inflateCopy(&z, const_cast<z_stream*>(&best->z)) != Z_OK) {
        z = z_stream{};
        if (inflateInit2(&z, 15 + 32) != Z_OK) throw Error("cannot start zlib");
        return std::nullopt;
    }
    resumed_ += best->z.total_out;
    return Resumed{uint64_t(best->z.total_out), best->filePosition};
}

uint64_t InflateCheckpoints::resumedBytes() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return resumed_;
}

} // namespace vdbdag::bridge::detail
