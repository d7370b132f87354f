// See InflateCheckpoints.h.
#include "vdb_bridge/detail/InflateCheckpoints.h"

namespace vdbdag::bridge::detail {

InflateCheckpoints::~InflateCheckpoints() {
    for (const auto& c : kept_) inflateEnd(&c->z);
}

void InflateCheckpoints::save(uint64_t decoded, const z_stream& z, uint64_t filePosition) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& c : kept_)
        if (c->decoded == decoded) return;
    auto c = std::make_unique<Checkpoint>();
    c->decoded = decoded;
    c->filePosition = filePosition;
    if (inflateCopy(&c->z, const_cast<z_stream*>(&z)) != Z_OK) return;
    c->z.next_in = nullptr;  // the reader's buffers, which it keeps
    c->z.avail_in = 0;
    c->z.next_out = nullptr;
    c->z.avail_out = 0;
    if (kept_.size() == kKept) {
        inflateEnd(&kept_.front()->z);
        kept_.pop_front();
    }
    kept_.push_back(std::move(c));
}

std::optional<InflateCheckpoints::Resumed> InflateCheckpoints::restore(uint64_t want, z_stream& z) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const Checkpoint* best = nullptr;
    for (const auto& c : kept_)
        if (c->decoded <= want && (!best || c->decoded > best->decoded)) best = c.get();
    if (!best || best->decoded == 0) return std::nullopt;
    // The fresh stream goes; its copy of the checkpoint takes its place (or,
    // should zlib fail to copy, a fresh stream again).
    inflateEnd(&z);
    z = z_stream{};
    if (inflateCopy(&z, const_cast<z_stream*>(&best->z)) != Z_OK) {
        z = z_stream{};
        inflateInit2(&z, 15 + 32);
        return std::nullopt;
    }
    resumed_ += best->decoded;
    return Resumed{best->decoded, best->filePosition};
}

} // namespace vdbdag::bridge::detail
