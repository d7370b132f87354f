// The traversal itself, shared by DagTracer.cpp and the fast paths that
// need their own per-box test inlined (SurfaceHit.cpp): an integer DDA over
// the compact SSVDAG with a stack of (node, mirror mask, attribute base)
// (SSVDAG paper §5, Listing 1; Dado et al. §4.1 for the offsets). See
// DagTracer.h for the arithmetic contract. Internal: include only from src/trace.
//
// The walk is compiled once per octant of the ray direction (the signs of
// its three components, -0.0 and 0 counting as positive), so the direction
// of every step and every boundary choice is a constant; it crosses a 4^3
// leaf (the narrow band of a level set) voxel by voxel in a loop of its
// own, without the cube arithmetic of the general step. The shader (gpu/shaders/
// trace_walk.glsl) walks the same boxes with the signs as variables; every
// crossing time is the same expression of the same integer boundary in both,
// so they agree bit for bit.
#pragma once
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include <vdbdag/dag_access.h>

#include "src/encoding/CompactDag.h"
#include "src/trace/DagTracer.h"
#include "src/trace/Ray.h"

namespace vdbdag::trace {
namespace detail {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr unsigned kMaxLevels = 64;

struct StackEntry {
    uint64_t pos;     // word index of the node's header in dag.inner
    uint64_t base;    // attribute entry of the node's first entry
    unsigned mirror;  // accumulated reflection
};

// floor() for |x| < 2^62 without a libm call (baseline x86-64 has no roundsd).
inline int64_t floorToInt(double x) {
    const int64_t i = int64_t(x);
    return i - int64_t(double(i) > x);
}

// The ray in the root cube's frame, for a direction whose sign on axis a is
// bit a of kNegative (set: d[a] < 0). An axis with d[a] == 0 counts as
// positive with d[a] = +0.0: every boundary ahead of its origin then has
// crossing time +inf, so it never steps.
template <unsigned kNegative>
struct OctantRay {
    double o[3], d[3];
    static constexpr bool negative(int a) { return (kNegative >> a) & 1u; }
    // The boundary through which the ray leaves voxel c on axis a.
    static constexpr int64_t exitOf(int a, int64_t c) { return negative(a) ? c : c + 1; }
    // Time at which the ray crosses the plane `boundary` on axis a.
    double crossing(int a, int64_t boundary) const { return (double(boundary) - o[a]) / d[a]; }
    // Voxel coordinate on axis a at time t, by the crossing times themselves
    // (DagTracer.h), within [lo, hi]; tIn/tOut get the crossing times of the
    // voxel's entry and exit boundaries along the ray (d[a] != 0). The
    // result is the one voxel whose [tIn, tOut) holds t (or the end of the
    // range), whatever the first guess: the guess only saves loop turns.
    int64_t voxelAt(int a, double t, int64_t lo, int64_t hi, double& tIn, double& tOut) const {
        const double p = o[a] + t * d[a];
        int64_t c;
        if (!(p > double(lo) - 1)) c = lo;  // also NaN
        else if (!(p < double(hi) + 2)) c = hi;
        else c = negative(a) ? -floorToInt(-p) - 1 : floorToInt(p);  // ceil(p) - 1 when moving down
        c = std::clamp(c, lo, hi);
        if (!negative(a)) {  // voxel c spans [crossing(c), crossing(c + 1))
            tOut = crossing(a, c + 1);
            while (c < hi && tOut <= t) { ++c; tOut = crossing(a, c + 1); }
            tIn = crossing(a, c);
            while (c > lo && tIn > t) { --c; tOut = tIn; tIn = crossing(a, c); }
        } else {  // voxel c spans [crossing(c + 1), crossing(c))
            tOut = crossing(a, c);
            while (c > lo && tOut <= t) { --c; tOut = crossing(a, c); }
            tIn = crossing(a, c + 1);
            while (c < hi && tIn > t) { ++c; tOut = tIn; tIn = crossing(a, c + 1); }
        }
        return c;
    }
};

// Leaf filter of walkRay that keeps every leaf.
struct EveryLeaf {
    bool operator()(uint64_t, unsigned) const { return true; }
};

// walkRay for one octant of directions; see walkRay below.
template <unsigned kNegative, bool kFirstHitOnly, class Visitor, class LeafFilter>
RayHit walkOctant(const encoding::CompactDag& dag, const TraceOptions& options, const OccupiedBox& box, const Ray& ray, Visitor& visit,
                  LeafFilter& keepLeaf) {
    using R = OctantRay<kNegative>;
    RayHit result;
    R r;
    for (int a = 0; a < 3; ++a) {
        r.o[a] = ray.origin[a] - double(dag.origin[a]);
        r.d[a] = ray.direction[a] == 0 ? 0.0 : ray.direction[a];  // -0.0 -> +0.0
    }
    const unsigned L = dag.log2Size;

    // Clip to the occupied box [lo, hi) (within the root cube [0, size)^3):
    // nothing outside it is occupied, and its faces are voxel boundaries, so
    // the walk is the same as from the root cube's faces, only shorter.
    double tEnter = ray.tMin, tExit = ray.tMax;
    int enterAxis = -1;
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0) {
            if (!(r.o[a] >= double(box.lo[a]) && r.o[a] < double(box.hi[a]))) return result;
            continue;
        }
        const double t0 = r.crossing(a, R::negative(a) ? box.hi[a] : box.lo[a]), t1 = r.crossing(a, R::negative(a) ? box.lo[a] : box.hi[a]);
        if (t0 > tEnter) { tEnter = t0; enterAxis = a; }
        tExit = std::min(tExit, t1);
    }
    if (!(tEnter < tExit)) return result;

    // The voxel at tEnter, the crossing time of its exit boundary on each
    // axis (inf if none: tNext[a] == crossing(a, exitOf(a, v[a])) always),
    // and the axes whose voxel boundary the ray crosses exactly at tEnter (an
    // edge or a corner crossing sets several; the hit face is the lowest of
    // them that is also a face of the hit box: a voxel, a tile or an LOD
    // node). Starting inside crosses nothing.
    int64_t v[3];
    double tNext[3];
    unsigned crossed = 0;
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0) {
            v[a] = std::clamp(floorToInt(r.o[a]), box.lo[a], box.hi[a] - 1);
            tNext[a] = kInf;
            continue;
        }
        double tIn;
        v[a] = r.voxelAt(a, tEnter, box.lo[a], box.hi[a] - 1, tIn, tNext[a]);
        if (enterAxis >= 0 && tIn == tEnter) crossed |= 1u << a;
    }
    double t = tEnter;

    StackEntry stack[kMaxLevels];
    unsigned depth = 0;
    stack[0] = {0, 0, dag.rootReflection};
    const uint16_t* inner = dag.inner.data();
    const uint64_t* leaves = dag.leaves.data();
    const unsigned innerLevels = unsigned(dag.innerLevelCount());
    const bool lod = options.lodScale > 0;
    uint32_t steps = 0;
    // The 4^3 leaf containing v, once reached: voxel steps inside it need no descent.
    bool inLeaf = false;
    uint64_t leafStored = 0, leafSpatial = 0, leafBase = 0;
    unsigned leafMirror = 0;

    auto makeHit = [&](uint64_t attribute, unsigned lodLevel) {
        int faceAxis = -1;
        const int64_t within = (int64_t(1) << lodLevel) - 1;
        for (int a = 0; a < 3 && faceAxis < 0; ++a)
            if (((crossed >> a) & 1u) && (v[a] & within) == (R::negative(a) ? within : 0)) faceAxis = a;
        result.hit = true;
        for (int a = 0; a < 3; ++a) result.voxel[a] = v[a] + dag.origin[a];
        // A hit at t = 0 reports +0.0: a tie of crossings at 0 is +0 on an
        // axis moving up and -0 on one moving down, and a hierarchical step
        // may take the tie from another axis than a voxel step (Vulkan).
        result.t = t == 0 ? 0.0 : t;
        result.attribute = attribute;
        result.faceAxis = int8_t(faceAxis);
        result.faceSign = faceAxis < 0 ? 0 : (R::negative(faceAxis) ? 1 : -1);
        result.lodLevel = uint8_t(lodLevel);
        result.steps = steps;
    };
    auto miss = [&]() { return kFirstHitOnly ? RayHit{} : result; };

    while (true) {
        // Find the box containing v: an occupied voxel/tile/LOD node (a hit)
        // or the largest empty cube, of log2 size `skip`.
        unsigned skip = 0;
        bool occupied = false;
        while (!inLeaf) {
            const StackEntry& node = stack[depth];
            const unsigned s = L - depth;  // log2 size of this node
            const uint16_t header = inner[node.pos];
            if (header == 0) {  // solid node: an active tile
                makeHit(node.base, s);
                occupied = true;
                skip = s;
                break;
            }
            const unsigned half = s - 1;
            const unsigned p = unsigned((v[0] >> half) & 1) | unsigned((v[1] >> half) & 1) << 1 | unsigned((v[2] >> half) & 1) << 2;
            const unsigned j = p ^ node.mirror;
            if (((header >> (2 * j)) & 3u) == 0) { skip = half; break; }
            uint64_t offset, attributeOffset;
            unsigned reflection;
            access::dagChildPointer(inner, node.pos, header, j, dag.offsetWords[depth], offset, reflection, attributeOffset);
            const unsigned mirror = node.mirror ^ reflection;
            const uint64_t base = node.base + attributeOffset;
            if (depth + 1 == innerLevels) {  // the child is a 4^3 leaf
                leafStored = leaves[offset];
                if (!keepLeaf(base, unsigned(std::popcount(leafStored)))) { skip = half; break; }
                leafSpatial = access::dagReflectBrick(leafStored, mirror);
                leafMirror = mirror;
                leafBase = base;
                inLeaf = true;
                break;
            }
            if (lod && double(int64_t(1) << half) <= options.lodScale * t) {
                makeHit(base, half);
                occupied = true;
                skip = half;
                break;
            }
            stack[depth + 1] = {dag.levelStart[depth + 1] + offset, base, mirror};
            ++depth;
        }

        if constexpr (kFirstHitOnly)
            if (occupied) return result;  // a tile or an LOD node

        if (inLeaf) {
            // Voxel by voxel through the 4^3 leaf: the cube step below with
            // skip 0 (every axis whose exit time is the least steps, the
            // others stay), until the ray leaves the leaf.
            uint64_t changed = 0;
            while (true) {
                const unsigned x = unsigned(v[0] & 3), y = unsigned(v[1] & 3), z = unsigned(v[2] & 3);
                const bool here = (leafSpatial >> (x + 4 * y + 16 * z)) & 1u;
                if (here) {
                    makeHit(leafBase + access::dagLeafRank(leafStored, access::dagStoredBit(x, y, z, leafMirror)), 0);
                    if constexpr (kFirstHitOnly) return result;
                }
                if (++steps > options.maxSteps) return miss();
                const double tNew = std::min(tNext[0], std::min(tNext[1], tNext[2]));
                if constexpr (!kFirstHitOnly)
                    if (here && visit(result, std::min(tNew, tExit))) return result;
                if (!(tNew < tExit)) return miss();  // left the occupied box or passed tMax
                crossed = 0;
                for (int a = 0; a < 3; ++a) {
                    if (tNext[a] != tNew) continue;
                    const int64_t next = R::negative(a) ? v[a] - 1 : v[a] + 1;
                    if (R::negative(a) ? next < box.lo[a] : next >= box.hi[a]) return miss();
                    tNext[a] = r.crossing(a, R::exitOf(a, next));
                    crossed |= 1u << a;
                    changed |= uint64_t(next ^ v[a]);
                    v[a] = next;
                }
                t = tNew;
                if (changed > 3) break;  // left the leaf
            }
            // Pop to the deepest stored node that still contains the new voxel.
            const unsigned keepLog2 = unsigned(std::bit_width(changed));
            if (L - depth < keepLog2) depth = L - keepLog2;
            inLeaf = false;
            continue;
        }

        // Leave the empty (or just visited) cube of size 2^skip containing v.
        if (++steps > options.maxSteps) return miss();
        const int64_t mask = (int64_t(1) << skip) - 1;
        int64_t far[3];  // the cube's last voxel along the ray on each axis
        double tc[3];    // the time the ray leaves it on each axis
        for (int a = 0; a < 3; ++a) {
            far[a] = R::negative(a) ? v[a] & ~mask : v[a] | mask;
            // The voxel's own exit when v is the cube's last voxel that way.
            tc[a] = v[a] == far[a] ? tNext[a] : r.crossing(a, R::exitOf(a, far[a]));
        }
        const double tNew = std::min(tc[0], std::min(tc[1], tc[2]));
        if constexpr (!kFirstHitOnly)
            if (occupied && visit(result, std::min(tNew, tExit))) return result;
        if (!(tNew < tExit)) return miss();  // left the occupied box or passed tMax
        int64_t next[3];
        crossed = 0;
        for (int a = 0; a < 3; ++a) {
            if (tc[a] == tNew) {
                next[a] = R::negative(a) ? far[a] - 1 : far[a] + 1;
                if (R::negative(a) ? next[a] < box.lo[a] : next[a] >= box.hi[a]) return miss();
                tNext[a] = r.crossing(a, R::exitOf(a, next[a]));
                crossed |= 1u << a;
            } else if (tNext[a] > tNew) {
                next[a] = v[a];  // no voxel boundary of this axis before tNew
            } else {
                double tIn;
                next[a] = R::negative(a) ? r.voxelAt(a, tNew, far[a], v[a], tIn, tNext[a]) : r.voxelAt(a, tNew, v[a], far[a], tIn, tNext[a]);
                if (next[a] != v[a] && tIn == tNew) crossed |= 1u << a;
            }
        }
        // Pop to the deepest stored node that still contains the new voxel.
        const uint64_t changed = uint64_t(next[0] ^ v[0]) | uint64_t(next[1] ^ v[1]) | uint64_t(next[2] ^ v[2]);
        const unsigned keepLog2 = unsigned(std::bit_width(changed));  // nodes of log2 size >= this still contain it
        if (L - depth < keepLog2) depth = L - keepLog2;
        for (int a = 0; a < 3; ++a) v[a] = next[a];
        t = tNew;
    }
}

// The traversal. With kFirstHitOnly it returns the first occupied box;
// otherwise it calls visit(hit, tLeave) for every occupied box (voxel, tile
// or LOD node) along the ray, in order, until visit returns true.
// `keepLeaf(firstEntry, entries)` may drop a 4^3 leaf whose voxels the
// caller would reject anyway (their attribute entries are the contiguous
// range [firstEntry, firstEntry + entries)): the walk then crosses it as
// empty space. The boxes visited after it are the same, with the same t and
// face, as a skip lands on the same voxel boundaries a voxel walk would.
template <bool kFirstHitOnly, class Visitor, class LeafFilter = EveryLeaf>
RayHit walkRay(const encoding::CompactDag& dag, const TraceOptions& options, const OccupiedBox& box, const Ray& ray, Visitor&& visit,
               LeafFilter&& keepLeaf = {}) {
    if (dag.empty()) return {};
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(ray.origin[a]) || !std::isfinite(ray.direction[a])) return {};
    if (std::isnan(ray.tMin) || std::isnan(ray.tMax)) return {};
    const unsigned octant = unsigned(ray.direction[0] < 0) | unsigned(ray.direction[1] < 0) << 1 | unsigned(ray.direction[2] < 0) << 2;
    switch (octant) {
    case 0: return walkOctant<0, kFirstHitOnly>(dag, options, box, ray, visit, keepLeaf);
    case 1: return walkOctant<1, kFirstHitOnly>(dag, options, box, ray, visit, keepLeaf);
    case 2: return walkOctant<2, kFirstHitOnly>(dag, options, box, ray, visit, keepLeaf);
    case 3: return walkOctant<3, kFirstHitOnly>(dag, options, box, ray, visit, keepLeaf);
    case 4: return walkOctant<4, kFirstHitOnly>(dag, options, box, ray, visit, keepLeaf);
    case 5: return walkOctant<5, kFirstHitOnly>(dag, options, box, ray, visit, keepLeaf);
    case 6: return walkOctant<6, kFirstHitOnly>(dag, options, box, ray, visit, keepLeaf);
    default: return walkOctant<7, kFirstHitOnly>(dag, options, box, ray, visit, keepLeaf);
    }
}

} // namespace detail

} // namespace vdbdag::trace
