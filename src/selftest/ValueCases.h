// The `values` group's building blocks, public so tests can run them with a
// tampered bound (a check that cannot fail checks nothing): a float or
// double field laid out on voxels, its lossless round trip compared bit for
// bit, and its lossy round trip checked value by value against a tolerance.
#pragma once
#include <cstdint>
#include <vector>

#include "src/attributes/ScalarTolerance.h"
#include "src/selftest/Selftest.h"
#include "src/selftest/SyntheticGrid.h"

namespace vdbdag::selftest {

// n values of `type` (raw bytes) on the voxels i -> (i % 32, i / 32 % 32, i / 1024).
SyntheticGrid scalarField(ValueType type, const std::vector<uint8_t>& raw);
SyntheticGrid floatField(const std::vector<float>& values);
SyntheticGrid doubleField(const std::vector<double>& values);

// Lossless: every value bit-identical after the file round trip.
Measurement checkLossless(const SyntheticGrid& field, const std::string& what);

// Encodes with `encodeWith`, then checks every decoded value against
// `checkAgainst` (normally the same tolerance): 0, -0.0, NaN (payload) and
// +-Inf bit-exact; every other value finite, of the same sign, within the
// bound (absolute E, or relative R|v|). Also measures the lossless encoding.
struct ToleranceCheck {
    Checks checks;
    uint64_t values = 0, changed = 0;
    uint64_t lostAllPrecision = 0;  // finite non-zero values whose relative error is >= 50% (collapsed towards 0)
    uint64_t distinctBefore = 0, distinctAfter = 0;
    double maxAbsError = 0, maxRelError = 0;
    uint64_t lossyFileBytes = 0, losslessFileBytes = 0;
};
ToleranceCheck checkTolerance(const SyntheticGrid& field, const attributes::ScalarTolerance& encodeWith,
                              const attributes::ScalarTolerance& checkAgainst);

} // namespace vdbdag::selftest
