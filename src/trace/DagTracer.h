// CPU reference tracer: rays straight through the compact SSVDAG, without
// decompressing it (SSVDAG paper §5, Listing 1; attributes as Dado et al.
// §4.1). The Vulkan shader (gpu/shaders/trace.comp, trace_walk.glsl) walks
// the same boxes with the same arithmetic, arranged for SIMD lanes instead
// of branches, and the two must return the same voxels.
//
// Traversal state is integer: the voxel the ray is in, and a stack of the
// stored nodes containing it with their accumulated mirror masks and
// attribute bases. The only floating-point quantity is the ray parameter t;
// every crossing time is computed the same way, (boundary - origin) / dir
// from an exact integer boundary, and the voxel at a time is derived from
// those same crossing times, so a hierarchical step lands exactly where a
// flat voxel-by-voxel walk (Amanatides-Woo) would, ties included.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "src/encoding/CompactDag.h"
#include "src/trace/Ray.h"

namespace vdbdag::trace {

struct TraceOptions {
    // Level-of-detail cut-off: a non-empty node whose size (in voxels) is at
    // most lodScale * t is taken as a hit (its first attribute). With a
    // pinhole camera, lodScale = lodPixels * (pixel footprint at t = 1);
    // 0 disables it.
    double lodScale = 0;
    // Upper bound on the nodes a ray may leave behind; a ray exceeding it
    // reports a miss (never reached by a valid DAG; guards corrupt input).
    uint32_t maxSteps = 1u << 24;
};

// The cells any occupied voxel or tile lies in, [lo, hi) relative to the
// root cube's corner: a conservative box from the top levels of the DAG.
struct OccupiedBox {
    int64_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
};
OccupiedBox occupiedBox(const encoding::CompactDag& dag, unsigned levels = 6);

class DagTracer {
public:
    // `dag` must be validated (encoding::validateCompact) and outlive the tracer.
    explicit DagTracer(const encoding::CompactDag& dag, TraceOptions options = {});

    RayHit trace(const Ray& ray) const;
    // Every occupied box along the ray in order (voxels, tiles, LOD nodes):
    // visit(box, tLeave) gets the box's entry as a RayHit and the parameter
    // where the ray leaves it; returning true stops the walk. For volumes.
    using SegmentVisitor = std::function<bool(const RayHit& box, double tLeave)>;
    void forEachSegment(const Ray& ray, const SegmentVisitor& visit) const;
    // Attribute entry of the active voxel at an index coordinate (point query).
    std::optional<uint64_t> find(const std::array<int64_t, 3>& voxel) const;
    // All rays, in parallel (TBB).
    void traceBatch(std::span<const Ray> rays, std::span<RayHit> hits) const;

    const encoding::CompactDag& dag() const { return dag_; }
    const TraceOptions& options() const { return options_; }
    const OccupiedBox& box() const { return box_; }

private:
    const encoding::CompactDag& dag_;
    TraceOptions options_;
    OccupiedBox box_;
};

} // namespace vdbdag::trace
