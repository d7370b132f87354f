// See ParallelFor.h.
#include "src/util/ParallelFor.h"

#include <tbb/parallel_for.h>

namespace vdbdag::util {

attributes::ParallelFor tbbParallelFor() {
    return [](size_t n, const std::function<void(size_t)>& body) { tbb::parallel_for(size_t(0), n, [&](size_t k) { body(k); }); };
}

} // namespace vdbdag::util
