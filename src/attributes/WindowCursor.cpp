// See WindowCursor.h.
#include "src/attributes/WindowCursor.h"

#include <algorithm>
#include <cstring>

#include "src/attributes/PredictedWindows.h"
#include "src/util/Error.h"

namespace vdbdag::attributes {

WindowCursor::WindowCursor(std::span<const uint8_t> payload, bool predicted, uint32_t valueSize, std::span<const uint64_t> layout, std::string what,
                           std::span<const coding::BrickPlace> places, unsigned ahead, ReferenceWindow reference,
                           std::shared_ptr<const WindowReference> offerTo)
    : payload_(payload),
      predicted_(predicted),
      layout_(layout),
      places_(places),
      reference_(std::move(reference)),
      offerTo_(std::move(offerTo)),
      what_(std::move(what)),
      ahead_(ahead) {
    dir_ = predicted ? readPredictedWindowDirectory(payload, valueSize, layout, what_) : readValueWindowDirectory(payload, what_);
    if (dir_.valueSize != valueSize)
        throw Error(what_ + ": holds " + std::to_string(dir_.valueSize) + "-byte values, expected " + std::to_string(valueSize));
}

// The windows decoding ahead finish before the cursor's spans may go.
WindowCursor::~WindowCursor() {
    for (std::future<std::vector<uint8_t>>& f : pending_)
        if (f.valid()) f.wait();
}

std::vector<uint8_t> WindowCursor::decode(size_t k) const {
    if (!predicted_) return decodeValueWindow(payload_, dir_, k, what_).decodeAll();
    std::vector<uint8_t> values = decodePredictedWindow(payload_, dir_, k, layout_, what_, places_, reference_);
    if (offerTo_) offerTo_->offer(k, values);
    return values;
}

// Windows are read in order (0, 1, ...): window k is the first pending one.
void WindowCursor::load(size_t k) {
    values_.clear();
    if (ahead_ == 0) {
        values_ = decode(k);
    } else {
        while (launched_ < dir_.windows.size() && launched_ <= k + ahead_) {
            pending_.push_back(std::async(std::launch::async, [this, j = launched_] { return decode(j); }));
            ++launched_;
        }
        std::future<std::vector<uint8_t>> next = std::move(pending_.front());
        pending_.pop_front();
        values_ = next.get();  // rethrows the window's error
    }
    window_ = k;
    loaded_ = true;
    at_ = 0;
}

void WindowCursor::read(uint64_t n, uint8_t* out) {
    const uint32_t vs = dir_.valueSize;
    while (n) {
        if (!loaded_ || at_ == dir_.windows[window_].entries) {
            const size_t next = loaded_ ? window_ + 1 : 0;
            if (next >= dir_.windows.size()) throw Error(what_ + ": read past its " + std::to_string(dir_.entries) + " entries");
            load(next);
        }
        const uint64_t take = std::min(n, dir_.windows[window_].entries - at_);
        std::memcpy(out, values_.data() + at_ * vs, size_t(take * vs));
        out += take * vs;
        at_ += take;
        n -= take;
    }
}

} // namespace vdbdag::attributes
