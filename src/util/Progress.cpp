// See Progress.h.
#include "src/util/Progress.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <unistd.h>

namespace vdbdag {
namespace {

std::atomic<bool> gQuiet{false};
constexpr int64_t kRedrawIntervalNs = 100'000'000;  // 10 redraws per second
constexpr int kBarWidth = 20;

int64_t nowNs() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// "42s", "3m07s", "2h05m".
std::string duration(double seconds) {
    char text[32];
    const long s = long(seconds + 0.5);
    if (s < 60) std::snprintf(text, sizeof text, "%lds", s);
    else if (s < 3600) std::snprintf(text, sizeof text, "%ldm%02lds", s / 60, s % 60);
    else std::snprintf(text, sizeof text, "%ldh%02ldm", s / 3600, (s % 3600) / 60);
    return text;
}

} // namespace

void Progress::setQuiet(bool quiet) { gQuiet = quiet; }
void setQuiet(bool quiet) { Progress::setQuiet(quiet); }
bool Progress::quiet() { return gQuiet; }
bool isQuiet() { return Progress::quiet(); }

Progress::Progress(std::string label, uint64_t total)
    : label_(std::move(label)), total_(total), startNs_(nowNs()), enabled_(!gQuiet && isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() {
    if (!enabled_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (!finished_ && drawn_) {
        std::fputs("\r\033[K", stderr);  // leave a clean line for an error message
        std::fflush(stderr);
    }
}

void Progress::advance(uint64_t n) {
    done_.fetch_add(n, std::memory_order_relaxed);
    if (enabled_) maybeDraw();
}

void Progress::set(uint64_t done) {
    done_.store(done, std::memory_order_relaxed);
    if (enabled_) maybeDraw();
}

void Progress::setLabel(std::string label) {
    if (!enabled_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    label_ = std::move(label);
    drawLocked(true);  // labels change rarely (per step): always show them
}

// Lock-free unless a redraw is due; one thread wins the redraw slot.
void Progress::maybeDraw() {
    const int64_t now = nowNs();
    int64_t next = nextDrawNs_.load(std::memory_order_relaxed);
    if (now < next) return;
    if (!nextDrawNs_.compare_exchange_strong(next, now + kRedrawIntervalNs, std::memory_order_relaxed)) return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (lock.owns_lock()) drawLocked(true);
}

void Progress::drawLocked(bool force) {
    if (finished_) return;
    const int64_t now = nowNs();
    if (!force && now < nextDrawNs_.load(std::memory_order_relaxed)) return;
    nextDrawNs_.store(now + kRedrawIntervalNs, std::memory_order_relaxed);
    const uint64_t done = std::min<uint64_t>(done_.load(std::memory_order_relaxed), total_);
    const int percent = total_ ? int(100.0 * double(done) / double(total_)) : 100;
    char bar[kBarWidth + 1];
    const int filled = percent * kBarWidth / 100;
    for (int i = 0; i < kBarWidth; ++i) bar[i] = i < filled ? '#' : '.';
    bar[kBarWidth] = 0;
    // Elapsed time, and once a little is done, the time left at this pace.
    const double elapsed = double(now - startNs_) * 1e-9;
    std::string timing;
    if (elapsed >= 1.0) {
        timing = " " + duration(elapsed);
        if (done > 0 && done < total_ && double(done) >= 0.02 * double(total_))
            timing += ", about " + duration(elapsed * double(total_ - done) / double(done)) + " left";
    }
    std::fprintf(stderr, "\r\033[K%s %3d%% [%s]%s", label_.c_str(), percent, bar, timing.c_str());
    std::fflush(stderr);
    drawn_ = true;
}

void Progress::finish() {
    if (!enabled_) return;
    done_ = total_;
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    drawLocked(true);
    std::fputs("\n", stderr);
    std::fflush(stderr);
    finished_ = true;
}

} // namespace vdbdag
