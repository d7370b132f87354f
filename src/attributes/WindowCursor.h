// A value channel at rest in windows (ValueWindows.h, PredictedWindows.h)
// read in attribute order, one window decoded at a time: what a reader that
// streams a layer (a dense decode cube by cube) holds instead of the whole
// channel. With read-ahead, the next windows decode on other threads while
// one is read (windows are independent: a scan's context-coded windows
// decode at about 12 MB/s a core, so a decode of one large scan waited on
// one core).
#pragma once
#include <cstdint>
#include <deque>
#include <future>
#include <span>
#include <string>
#include <vector>

#include "src/attributes/PredictedWindows.h"
#include "src/attributes/ValueWindows.h"

namespace vdbdag::attributes {

class WindowCursor {
public:
    // `payload` (and for predicted windows the DAG's attributeLayout,
    // `layout`, and attributePlaces, `places`) must outlive the cursor. Checks the directory; each window
    // is checked when it is reached (throws vdbdag::Error starting with `what`).
    // `ahead`: windows decoded ahead of the one being read, each on a
    // thread of its own (0: none; the cursor then holds one decoded window,
    // else up to 1 + ahead).
    WindowCursor(std::span<const uint8_t> payload, bool predicted, uint32_t valueSize, std::span<const uint64_t> layout, std::string what,
                 std::span<const coding::BrickPlace> places, unsigned ahead = 0, ReferenceWindow reference = {},
                 std::shared_ptr<const WindowReference> offerTo = nullptr);
    WindowCursor(const WindowCursor&) = delete;
    WindowCursor& operator=(const WindowCursor&) = delete;
    ~WindowCursor();
    uint64_t entries() const { return dir_.entries; }
    // Copies the next `n` entries (n * valueSize bytes) to `out`.
    void read(uint64_t n, uint8_t* out);

private:
    void load(size_t k);
    std::vector<uint8_t> decode(size_t k) const;
    std::span<const uint8_t> payload_;
    bool predicted_;
    std::span<const uint64_t> layout_;
    std::span<const coding::BrickPlace> places_;
    ReferenceWindow reference_;  // a series' reference (PredictedWindows.h), or empty
    std::shared_ptr<const WindowReference> offerTo_;  // the reference each decoded window is offered to (a series' next grid's), or null
    std::string what_;
    WindowDirectory dir_;
    size_t window_ = 0;            // the window in `values_`
    bool loaded_ = false;
    std::vector<uint8_t> values_;  // its entries
    uint64_t at_ = 0;              // entries of it already read
    unsigned ahead_ = 0;
    size_t launched_ = 0;                                  // windows started ahead so far (0, 1, ... in order)
    std::deque<std::future<std::vector<uint8_t>>> pending_;  // windows window_ + 1, ... being decoded
};

} // namespace vdbdag::attributes
