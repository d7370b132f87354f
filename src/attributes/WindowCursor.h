// A value channel at rest in windows (ValueWindows.h, PredictedWindows.h)
// read in attribute order, one window decoded at a time: what a reader that
// streams a layer (a dense decode cube by cube) holds instead of the whole
// channel.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/attributes/ValueWindows.h"

namespace vdbdag::attributes {

class WindowCursor {
public:
    // `payload` (and for predicted windows the DAG's attributeLayout,
    // `layout`, and attributePlaces, `places`) must outlive the cursor. Checks the directory; each window
    // is checked when it is reached (throws vdbdag::Error starting with `what`).
    WindowCursor(std::span<const uint8_t> payload, bool predicted, uint32_t valueSize, std::span<const uint64_t> layout, std::string what,
                 std::span<const coding::BrickPlace> places);
    uint64_t entries() const { return dir_.entries; }
    // Copies the next `n` entries (n * valueSize bytes) to `out`.
    void read(uint64_t n, uint8_t* out);

private:
    void load(size_t k);
    std::span<const uint8_t> payload_;
    bool predicted_;
    std::span<const uint64_t> layout_;
    std::span<const coding::BrickPlace> places_;
    std::string what_;
    WindowDirectory dir_;
    size_t window_ = 0;            // the window in `values_`
    bool loaded_ = false;
    std::vector<uint8_t> values_;  // its entries
    uint64_t at_ = 0;              // entries of it already read
};

} // namespace vdbdag::attributes
