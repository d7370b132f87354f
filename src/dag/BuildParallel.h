// The DAG builder's loops over independent items and its sort: on TBB's
// threads in the core library, one after another in the public reader
// library (VDBDAG_BUILDING_LIBRARY), which links no thread pool and builds
// only the DAG of a level set's inside (format/InactiveSignedFill.h). The
// results are the same either way: each item is computed alone, and the
// sort's order is total (the Morton order of distinct cells).
#pragma once
#include <algorithm>
#include <cstddef>

#ifndef VDBDAG_BUILDING_LIBRARY
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#endif

namespace vdbdag::dag::detail {

// body(begin, end) over [0, n), in pieces of about `grain` items.
template <typename Body>
void forEachRange(size_t n, size_t grain, Body&& body) {
#ifdef VDBDAG_BUILDING_LIBRARY
    (void)grain;
    if (n) body(size_t(0), n);
#else
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain), [&](const tbb::blocked_range<size_t>& r) { body(r.begin(), r.end()); });
#endif
}

template <typename It, typename Less>
void sortRange(It begin, It end, Less less) {
#ifdef VDBDAG_BUILDING_LIBRARY
    std::sort(begin, end, less);
#else
    tbb::parallel_sort(begin, end, less);
#endif
}

} // namespace vdbdag::dag::detail
