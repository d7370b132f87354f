// Atomic output (DESIGN.md invariant 6): write to a temporary name in the
// destination's folder, fsync, then rename over the destination. On failure
// the temporary is removed, so no partial output is ever left behind.
#pragma once
#include <cstdint>
#include <functional>
#include <span>
#include <string>

namespace vdbdag {

// Writes `bytes` to `path` atomically; throws vdbdag::Error naming the path.
void writeFileAtomically(const std::string& path, std::span<const uint8_t> bytes);

// For writers that need a file name (e.g. OpenVDB's io::File): calls
// `writeTo(temporaryPath)`, then renames it to `path`. If `writeTo` throws,
// the temporary is removed and the exception propagates.
void writeViaTemporary(const std::string& path, const std::function<void(const std::string& temporaryPath)>& writeTo);

} // namespace vdbdag
