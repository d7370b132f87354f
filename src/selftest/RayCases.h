// The `rays` group's comparison, public so a test can feed it a tracer and
// a reference that disagree (a check that cannot fail checks nothing):
// traces every ray with the CPU tracer over `traced` and with the exact
// rational reference over `reference` (normally the same DAG) and checks
// zero mismatches, steps <= stepBound and no NaN t.
#pragma once
#include <cstdint>
#include <span>

#include "src/encoding/CompactDag.h"
#include "src/selftest/Selftest.h"
#include "src/trace/Ray.h"

namespace vdbdag::selftest {

Measurement compareRays(const encoding::CompactDag& traced, const encoding::CompactDag& reference, std::span<const trace::Ray> rays,
                        uint64_t stepBound);

} // namespace vdbdag::selftest
