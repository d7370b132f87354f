// See Progress.h.
#include "src/util/Progress.h"

#include <cstdio>
#include <unistd.h>

namespace vdbdag {
namespace {
std::atomic<bool> gQuiet{false};
}

void Progress::setQuiet(bool quiet) { gQuiet = quiet; }

Progress::Progress(std::string label, uint64_t total)
    : label_(std::move(label)), total_(total), enabled_(!gQuiet && isatty(STDERR_FILENO)) {}

Progress::~Progress() { finish(); }

void Progress::advance(uint64_t n) {
    done_ += n;
    draw(false);
}

void Progress::set(uint64_t done) {
    done_ = done;
    draw(false);
}

void Progress::setLabel(std::string label) {
    if (!enabled_) return;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        label_ = std::move(label);
    }
    draw(true);
}

void Progress::draw(bool force) {
    if (!enabled_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!force && now - lastDraw_ < std::chrono::milliseconds(100)) return;
    lastDraw_ = now;
    const uint64_t done = std::min<uint64_t>(done_, total_);
    const int percent = total_ ? int(100 * done / total_) : 100;
    char bar[21];
    for (int i = 0; i < 20; ++i) bar[i] = i < percent / 5 ? '#' : '.';
    bar[20] = 0;
    std::fprintf(stderr, "\r\033[K%s %3d%% [%s]", label_.c_str(), percent, bar);
    std::fflush(stderr);
}

void Progress::finish() {
    if (!enabled_) return;
    done_ = total_;
    draw(true);
    std::lock_guard<std::mutex> lock(mutex_);
    if (!finished_) {
        std::fprintf(stderr, "\n");
        finished_ = true;
    }
}

} // namespace vdbdag
