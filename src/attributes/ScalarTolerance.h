// Lossy scalar channels with a guarantee, like NanoVDB's FpN tolerance:
// `--abs-error E` rounds every finite value to a multiple of 2E (error <= E;
// an int32/int64 value to a multiple of 2 floor(E) + 1, error <= floor(E),
// JPEG-LS's NEAR: the value coder then codes the multiples);
// `--rel-error R` rounds |v| on a logarithmic grid of ratio (1+R)^2 (error
// <= R|v|, so it holds for values spanning 1e-30..1e30). Every quantised
// value is checked against the bound and kept exact if rounding would break
// it; 0, -0.0, NaN (with payload) and +-Inf are always kept exact, and a
// value rounded to zero keeps its sign bit (level-set classification). Fewer
// distinct values is what the palette compressor then turns into bits.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "src/volume/GridRecord.h"

namespace vdbdag::attributes {

struct ScalarTolerance {
    enum class Mode : uint8_t { Exact = 0, Absolute = 1, Relative = 2 };
    Mode mode = Mode::Exact;
    double bound = 0;
};

// What a lossy setting cost, measured on every entry (Benthin et al.'s habit
// of reporting max and RMS error next to the size).
struct ToleranceReport {
    ScalarTolerance tolerance;
    uint64_t entries = 0, changed = 0, keptExact = 0;
    double maxAbsError = 0, meanAbsError = 0, rmsError = 0, maxRelError = 0;
};

// Quantises float or double values (raw bytes, attribute order) in place,
// chunk after chunk in attribute order, so an encoder in bounded memory
// quantises each cube's values as they are gathered; the report (its sums
// taken in the same order) is the same however the values were cut.
// Integers take the absolute bound only; other types are left untouched
// (the report then says 0 changed).
class ScalarQuantizer {
public:
    ScalarQuantizer(ValueType type, const ScalarTolerance& tolerance);
    void apply(std::span<uint8_t> values);
    ToleranceReport finish() const;

private:
    template <typename T>
    void quantise(std::span<uint8_t> bytes);
    template <typename T>
    void quantiseIntegers(std::span<uint8_t> bytes);
    ValueType type_;
    ToleranceReport report_;
    double sumAbs_ = 0, sumSq_ = 0;
};

// All the values at once.
ToleranceReport applyScalarTolerance(std::vector<uint8_t>& values, ValueType type, const ScalarTolerance& tolerance);

std::string describe(const ScalarTolerance& tolerance);

} // namespace vdbdag::attributes
