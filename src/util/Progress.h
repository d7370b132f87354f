// A one-line progress display on stderr ("encode: building levels  42%
// [########............] 12s, about 16s left"), drawn only when stderr is a terminal and silent
// when it is piped or redirected (or after setQuiet(true)); at most ~10
// redraws per second; advance() and set() are thread-safe and cost one atomic
// add plus a clock read when nothing is drawn.
#pragma once
#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

namespace vdbdag {

class Progress {
public:
    Progress(std::string label, uint64_t total);
    ~Progress();  // clears an unfinished line (e.g. when an error unwinds)
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    void advance(uint64_t n = 1);
    void set(uint64_t done);
    void finish();                      // draws 100% and ends the line
    void setLabel(std::string label);  // e.g. the current step

    static void setQuiet(bool quiet);  // e.g. for --json output
    static bool quiet();
    bool enabled() const { return enabled_; }

private:
    void maybeDraw();
    void drawLocked(bool force);
    std::string label_;
    const uint64_t total_;
    const int64_t startNs_;
    std::atomic<uint64_t> done_{0};
    std::atomic<int64_t> nextDrawNs_{0};
    const bool enabled_;
    bool finished_ = false;
    bool drawn_ = false;
    std::mutex mutex_;
};

// Silences every progress line created afterwards (global).
void setQuiet(bool quiet);
bool isQuiet();

} // namespace vdbdag
