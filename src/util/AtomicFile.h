// Atomic output (DESIGN.md invariant 6): write to a temporary name in the
// destination's folder, fsync, then rename over the destination. On failure,
// or on SIGINT / SIGTERM / SIGHUP (TemporaryFiles.h), the temporary is
// removed, so no partial output is ever left behind. The destination must be
// absent or a regular file: links, devices, FIFOs and folders are refused.
// Whether an existing file may be replaced at all is the caller's decision
// (OutputPath.h).
#pragma once
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <span>
#include <string>

namespace vdbdag {

// Marks `path` as an output that must not exist when it is written (a new
// output, no --force: OutputPath.h calls this): its rename will not replace
// a file another program created meanwhile, and reports it instead, until
// it has been written once. isNew false clears the mark (--force).
void expectNewFile(const std::string& path, bool isNew = true);

// Renames a finished temporary `from` (beside `path`) to `path` by the
// rules above (never over a file that appeared meanwhile for a new output),
// for writers that place several files themselves (a .vtm and its pieces).
// On failure `from` is removed and vdbdag::Error thrown naming `path`.
void moveIntoPlace(const std::string& from, const std::string& path);

// Writes `bytes` to `path` atomically; throws vdbdag::Error naming the path.
void writeFileAtomically(const std::string& path, std::span<const uint8_t> bytes);

// For writers that write a stream (e.g. OpenVDB's archive): `writeTo` writes
// to `out`, whose every write is checked (a full disk is an Error, whatever
// the writer does with the stream's state).
void writeStreamAtomically(const std::string& path, const std::function<void(std::ostream& out)>& writeTo);

// For writers that need a file name (VTK's, OpenImageIO's): calls
// `writeTo(temporaryPath)` (the temporary ends with `suffix`, for writers
// that pick the format by extension), then renames it to `path`. If
// `writeTo` throws, the temporary is removed and the exception propagates;
// `writeTo` must itself report failed writes.
void writeViaTemporary(const std::string& path, const std::function<void(const std::string& temporaryPath)>& writeTo, const std::string& suffix = "",
                       bool folder = false);

} // namespace vdbdag
