// The exact integer reference for the tracers (issue 4, DESIGN.md
// invariant 5): a brute-force walk over every decoded voxel and tile with
// exact rational arithmetic, no floating point at all. For each occupied box
// it computes the exact, half-open interval of ray parameters over which the
// ray is inside it (with the face convention of Ray.h) and returns the box
// entered first. Rays must have components that are multiples of 2^-16 with
// magnitude below 2^40 (so every product fits 128 bits); `representable`
// tells. Slow (O(boxes) per ray): for tests and `vdbdag selftest` on small
// grids.
#pragma once
#include <optional>
#include <vector>

#include "src/encoding/CompactDag.h"
#include "src/trace/Ray.h"

namespace vdbdag::trace {

class ExactRayReference {
public:
    // Decodes every voxel and tile of `dag` (at most maxBoxes, else throws).
    explicit ExactRayReference(const encoding::CompactDag& dag, size_t maxBoxes = size_t(1) << 22);

    static bool representable(const Ray& ray);
    // Throws vdbdag::Error if !representable(ray).
    RayHit trace(const Ray& ray) const;
    // Every occupied box the ray overlaps over a positive length (or starts
    // in), by entry parameter.
    std::vector<RayHit> traceAll(const Ray& ray) const;
    // Attribute entry of the active voxel (or tile) at an index coordinate.
    std::optional<uint64_t> find(const std::array<int64_t, 3>& voxel) const;

private:
    struct Box {
        int64_t min[3];
        int64_t size;
        uint64_t attribute;
        unsigned log2Size;
    };
    std::vector<Box> boxes_;
};

} // namespace vdbdag::trace
