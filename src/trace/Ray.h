// Rays and hits of the DAG tracers (CPU reference and Vulkan), in the DAG's
// *cell space*: index space shifted by half a voxel, so voxel (i, j, k)
// occupies the half-open cube [i, i+1) x [j, j+1) x [k, k+1). (OpenVDB puts
// voxel centres on integers; a renderer adds 0.5 to index-space positions.)
//
// A point exactly on a voxel face belongs to the voxel the ray is moving
// into: along an axis with direction > 0 the ray at parameter t is in voxel
// floor(p), with direction < 0 in ceil(p) - 1, with direction 0 (or -0.0) in
// floor(p). So the hit voxel is the first set voxel the ray overlaps over a
// positive length, or the voxel it starts in (DESIGN.md invariant 5).
#pragma once
#include <array>
#include <cstdint>
#include <limits>

namespace vdbdag::trace {

struct Ray {
    std::array<double, 3> origin{0, 0, 0};
    std::array<double, 3> direction{0, 0, 1};  // need not be normalised; components may be 0 or -0.0
    double tMin = 0;
    double tMax = std::numeric_limits<double>::infinity();
};

struct RayHit {
    bool hit = false;
    std::array<int64_t, 3> voxel{0, 0, 0};  // index coordinate of the hit voxel
    double t = 0;                            // ray parameter where the ray enters it (or tMin)
    uint64_t attribute = 0;                  // attribute entry (value index) of the voxel or its tile
    int8_t faceAxis = -1;                    // axis of the face the ray entered through; -1: started inside
    int8_t faceSign = 0;                     // outward normal sign of that face (-1 or +1)
    uint8_t lodLevel = 0;                    // log2 size of the node accepted as a hit (0: a voxel)
    uint32_t steps = 0;                      // nodes left behind on the way (for statistics)
    uint8_t wideSteps = 0;                   // Vulkan walk: steps decided in doubles, up to 127 (statistics; 0 on the CPU)
};

} // namespace vdbdag::trace
