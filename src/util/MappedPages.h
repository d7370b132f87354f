// Pages of a file that a library mapped into this process (OpenVDB's
// delayed loading maps the whole .vdb file while a grid's leaves still
// refer to it): found by the file's device and inode in /proc/self/maps and
// dropped from the resident set (madvise MADV_DONTNEED; the mapping is
// read-only, so a later touch reads the page again). Linux only; elsewhere
// it finds nothing and does nothing.
//
// The mappings are looked up at each call, never kept: once the library
// unmaps the file, its address range is soon reused by anonymous memory,
// which MADV_DONTNEED would silently zero.
#pragma once
#include <cstddef>
#include <string>

namespace vdbdag {

// Drops every resident page of the current read-only mappings of `path`;
// returns how many mappings there were.
size_t releaseMappedPages(const std::string& path);

} // namespace vdbdag
