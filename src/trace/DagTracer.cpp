// CPU traversal of the compact SSVDAG; see DagTracer.h for the arithmetic
// contract and CompactDag.cpp for the word layout. Keep in step with
// gpu/shaders/trace.comp.
#include "src/trace/DagTracer.h"
#include "src/trace/DagWalk.h"
#include "src/encoding/DagDescent.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include <tbb/parallel_for.h>

namespace vdbdag::trace {
OccupiedBox occupiedBox(const encoding::CompactDag& dag, unsigned levels) {
    OccupiedBox box;
    if (dag.empty()) return box;
    for (int a = 0; a < 3; ++a) { box.lo[a] = INT64_MAX; box.hi[a] = INT64_MIN; }
    const unsigned maxDepth = std::min<unsigned>(unsigned(dag.innerLevelCount()) - 1, levels);
    // From a root at (0, 0, 0): the box is relative to the DAG's origin.
    encoding::descendFrom(
        dag, 0, 0, encoding::NodePlace{0, 0, 0, dag.rootReflection},
        [&](size_t depth, uint64_t, uint16_t header, const encoding::NodePlace& at) {
            if (header != 0 && depth < maxDepth) return true;
            const int64_t c[3] = {at.x, at.y, at.z}, size = int64_t(1) << (dag.log2Size - depth);
            for (int a = 0; a < 3; ++a) { box.lo[a] = std::min(box.lo[a], c[a]); box.hi[a] = std::max(box.hi[a], c[a] + size); }
            return false;
        },
        [](uint64_t, const encoding::NodePlace&) {});  // maxDepth stops above the leaves
    return box;
}

DagTracer::DagTracer(const encoding::CompactDag& dag, TraceOptions options) : dag_(dag), options_(options), box_(occupiedBox(dag)) {}

RayHit DagTracer::trace(const Ray& ray) const {
    return detail::walkRay<true>(dag_, options_, box_, ray, [](const RayHit&, double) { return true; });
}

void DagTracer::forEachSegment(const Ray& ray, const SegmentVisitor& visit) const {
    detail::walkRay<false>(dag_, options_, box_, ray, visit);
}

std::optional<uint64_t> DagTracer::find(const std::array<int64_t, 3>& voxel) const {
    const encoding::CompactDag& dag = dag_;
    if (dag.empty()) return std::nullopt;
    int64_t v[3];
    const int64_t size = int64_t(1) << dag.log2Size;
    for (int a = 0; a < 3; ++a) {
        v[a] = voxel[a] - dag.origin[a];
        if (v[a] < 0 || v[a] >= size) return std::nullopt;
    }
    uint64_t pos = 0, base = 0;
    unsigned mirror = dag.rootReflection;
    const unsigned innerLevels = unsigned(dag.innerLevelCount());
    const uint64_t x = uint64_t(v[0]), y = uint64_t(v[1]), z = uint64_t(v[2]);
    for (unsigned depth = 0;; ++depth) {
        const uint16_t header = dag.inner[pos];
        if (header == 0) return base;
        uint64_t offset;
        if (!access::dagDescend(dag.inner.data(), pos, header, x, y, z, dag.log2Size - depth - 1, dag.offsetWords[depth], mirror, base, offset))
            return std::nullopt;
        if (depth + 1 == innerLevels) {
            uint64_t entry;
            if (!access::dagLeafEntry(dag.leaves[offset], x, y, z, mirror, base, entry)) return std::nullopt;
            return entry;
        }
        pos = dag.levelStart[depth + 1] + offset;
    }
}

void DagTracer::traceBatch(std::span<const Ray> rays, std::span<RayHit> hits) const {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 1024), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) hits[i] = trace(rays[i]);
    });
}

} // namespace vdbdag::trace
