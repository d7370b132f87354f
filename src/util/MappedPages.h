// Pages of a file that a library mapped into this process (OpenVDB's
// delayed loading maps the whole .vdb file and never unmaps it while a grid
// lives): found by the file's device and inode in /proc/self/maps, and
// dropped from the resident set on request (madvise MADV_DONTNEED; the
// mapping is read-only, so a later touch reads the page again). Linux only;
// elsewhere it finds nothing and does nothing.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace vdbdag {

class MappedPages {
public:
    MappedPages() = default;
    // The current read-only mappings of `path` (none if it is not mapped).
    explicit MappedPages(const std::string& path);
    // Drops every resident page of those mappings from this process.
    void release() const;
    size_t mappings() const { return ranges_.size(); }

private:
    std::vector<std::pair<void*, size_t>> ranges_;
};

} // namespace vdbdag
