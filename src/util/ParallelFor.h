// TBB's parallel_for as the attributes::ParallelFor that decoders of value
// windows take (PredictedWindows.h): the core library's thread pool, handed
// to code that the public reader library shares and that links no pool.
#pragma once
#include "src/attributes/PredictedWindows.h"

namespace vdbdag::util {

attributes::ParallelFor tbbParallelFor();

} // namespace vdbdag::util
