// Temporary files and folders that must not outlive the process: every
// atomic output's temporary (AtomicFile.h) is registered here while it
// exists. SIGINT, SIGTERM and SIGHUP remove them all before the process ends
// with that signal (installInterruptCleanup); so does running out of memory
// (the CLI's new-handler calls removeAllTemporaries). What SIGKILL leaves
// behind is named ".NAME.tmp.PID.*" beside NAME, so the next atomic write of
// NAME removes the temporaries of processes that no longer run
// (removeStaleTemporaries).
#pragma once
#include <string>

namespace vdbdag {

// While alive, `path` (a file, or with `folder` a folder and what it holds)
// is removed if the process is interrupted. Not copyable; at most 64 live at
// once (more throw Error).
class TemporaryGuard {
public:
    explicit TemporaryGuard(const std::string& path, bool folder = false);
    ~TemporaryGuard();
    TemporaryGuard(const TemporaryGuard&) = delete;
    TemporaryGuard& operator=(const TemporaryGuard&) = delete;

private:
    int slot_;
};

// Installs the SIGINT / SIGTERM / SIGHUP handlers (once; the CLI calls it).
void installInterruptCleanup();

// Removes every registered temporary; async-signal-safe.
void removeAllTemporaries() noexcept;

// The temporary name for an output `path`: ".NAME.tmp.PID.RANDOM" in the
// same folder, then `suffix` (e.g. ".png" for writers that choose the format
// by extension).
std::string temporaryNameFor(const std::string& path, const std::string& suffix = "");

// Removes ".NAME.tmp.PID.*" entries beside `path` whose process PID no
// longer runs (what a SIGKILL during an earlier write left). Best effort.
void removeStaleTemporaries(const std::string& path) noexcept;

} // namespace vdbdag
