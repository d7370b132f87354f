// A one-line progress display on stderr ("encode  42% [########......]"),
// drawn only when stderr is a terminal and quiet when piped; at most ~10
// redraws per second; advance() is thread-safe.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace vdbdag {

class Progress {
public:
    Progress(std::string label, uint64_t total);
    ~Progress();
    void advance(uint64_t n = 1);
    void set(uint64_t done);
    void finish();
    void setLabel(std::string label);  // e.g. the current step

    static void setQuiet(bool quiet);  // e.g. for --json output

private:
    void draw(bool force);
    std::string label_;
    uint64_t total_;
    std::atomic<uint64_t> done_{0};
    bool enabled_;
    bool finished_ = false;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point lastDraw_{};
};

} // namespace vdbdag
