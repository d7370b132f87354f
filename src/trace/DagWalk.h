// The traversal itself, shared by DagTracer.cpp and the fast paths that
// need their own per-box test inlined (SurfaceHit.cpp): an integer DDA over
// the compact SSVDAG with a stack of (node, mirror mask, attribute base)
// (SSVDAG paper §5, Listing 1; Dado et al. §4.1 for the offsets). See
// DagTracer.h for the arithmetic contract. Internal: include only from src/trace.
#pragma once
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "src/dag/Reflection.h"
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

// The ray in the root cube's frame, with the per-axis crossing times.
struct LocalRay {
    double o[3], d[3];
    // Time at which the ray crosses the plane `boundary` on axis a (d[a] != 0).
    double crossing(int a, int64_t boundary) const { return (double(boundary) - o[a]) / d[a]; }
    // Voxel coordinate on axis a at time t, by the crossing times themselves
    // (DagTracer.h), within [lo, hi]; tIn/tOut get the crossing times of the
    // voxel's entry and exit boundaries along the ray (d[a] != 0).
    int64_t voxelAt(int a, double t, int64_t lo, int64_t hi, double& tIn, double& tOut) const {
        const double p = o[a] + t * d[a];
        int64_t c;
        if (!(p > double(lo) - 1)) c = lo;  // also NaN
        else if (!(p < double(hi) + 2)) c = hi;
        else c = d[a] > 0 ? floorToInt(p) : -floorToInt(-p) - 1;  // ceil(p) - 1
        c = std::clamp(c, lo, hi);
        if (d[a] > 0) {  // voxel c spans [crossing(c), crossing(c + 1))
            tOut = crossing(a, c + 1);
            while (c < hi && tOut <= t) { ++c; tOut = crossing(a, c + 1); }
            tIn = crossing(a, c);
            while (c > lo && tIn > t) { --c; tOut = tIn; tIn = crossing(a, c); }
        } else {         // voxel c spans [crossing(c + 1), crossing(c))
            tOut = crossing(a, c);
            while (c > lo && tOut <= t) { --c; tOut = crossing(a, c); }
            tIn = crossing(a, c + 1);
            while (c < hi && tIn > t) { ++c; tOut = tIn; tIn = crossing(a, c + 1); }
        }
        return c;
    }
    int64_t voxelAt(int a, double t, int64_t lo, int64_t hi) const {
        if (d[a] == 0) return std::clamp(floorToInt(o[a]), lo, hi);
        double tIn, tOut;
        return voxelAt(a, t, lo, hi, tIn, tOut);
    }
};

inline unsigned tagWords(unsigned tag) { return tag == 0 ? 0 : tag == 1 ? 1 : 2; }

// Reads stored child slot j of the node at `pos` (whose header is nonzero).
inline void readChildPointer(const uint16_t* inner, uint64_t pos, uint16_t header, unsigned j, unsigned offsetWords,
                             uint64_t& offset, unsigned& reflection, uint64_t& attributeOffset) {
    // Tags of the slots before j: 00 none, 01 one word, 1x two words.
    const unsigned earlier = header & ((1u << (2 * j)) - 1);
    const unsigned before = unsigned(std::popcount((earlier | (earlier >> 1)) & 0x5555u));
    uint64_t at = pos + 1 + before + unsigned(std::popcount((earlier >> 1) & 0x5555u));
    if (before > 1) at += uint64_t(before - 1) * offsetWords;
    const unsigned tag = (header >> (2 * j)) & 3u;
    const uint16_t w0 = inner[at];
    reflection = unsigned(w0 >> 13);
    if (tag == 1) {
        offset = w0 & 0x1FFFu;
        at += 1;
    } else {
        offset = (uint64_t(tag & 1u) << 29) | (uint64_t(w0 & 0x1FFFu) << 16) | inner[at + 1];
        at += 2;
    }
    attributeOffset = 0;
    if (before > 0)
        for (unsigned w = 0; w < offsetWords; ++w) attributeOffset |= uint64_t(inner[at + w]) << (16 * w);
}

// Bit of a 4^3 brick stored under reflection m for spatial voxel (x, y, z).
inline unsigned storedBit(unsigned x, unsigned y, unsigned z, unsigned m) {
    if (m & 1u) x = 3 - x;
    if (m & 2u) y = 3 - y;
    if (m & 4u) z = 3 - z;
    return x + 4 * y + 16 * z;
}

// Leaf filter of walkRay that keeps every leaf.
struct EveryLeaf {
    bool operator()(uint64_t, unsigned) const { return true; }
};

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
    RayHit result;
    if (dag.empty()) return result;
    LocalRay r;
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(ray.origin[a]) || !std::isfinite(ray.direction[a])) return result;
        r.o[a] = ray.origin[a] - double(dag.origin[a]);
        r.d[a] = ray.direction[a];
    }
    if (std::isnan(ray.tMin) || std::isnan(ray.tMax)) return result;
    const unsigned L = dag.log2Size;
    const int64_t size = int64_t(1) << L;

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
        const double t0 = r.crossing(a, r.d[a] > 0 ? box.lo[a] : box.hi[a]), t1 = r.crossing(a, r.d[a] > 0 ? box.hi[a] : box.lo[a]);
        if (t0 > tEnter) { tEnter = t0; enterAxis = a; }
        tExit = std::min(tExit, t1);
    }
    if (!(tEnter < tExit)) return result;

    // The voxel at tEnter, the crossing time of the voxel boundary ahead on
    // each axis (inf if none), and the axes whose voxel boundary the ray
    // crosses exactly at tEnter (an edge or a corner crossing sets several;
    // the hit face is the lowest of them that is also a face of the hit box:
    // a voxel, a tile or an LOD node). Starting inside crosses nothing.
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
    uint32_t steps = 0;
    // The 4^3 leaf containing v, once reached: voxel steps inside it need no descent.
    bool inLeaf = false;
    uint64_t leafStored = 0, leafSpatial = 0, leafBase = 0;
    unsigned leafMirror = 0;

    bool pending = false;  // result holds an occupied box not yet passed to visit
    auto makeHit = [&](uint64_t attribute, unsigned lodLevel) {
        int faceAxis = -1;
        const int64_t within = (int64_t(1) << lodLevel) - 1;
        for (int a = 0; a < 3 && faceAxis < 0; ++a)
            if (((crossed >> a) & 1u) && (v[a] & within) == (r.d[a] > 0 ? 0 : within)) faceAxis = a;
        result.hit = true;
        for (int a = 0; a < 3; ++a) result.voxel[a] = v[a] + dag.origin[a];
        result.t = t;
        result.attribute = attribute;
        result.faceAxis = int8_t(faceAxis);
        result.faceSign = faceAxis < 0 ? 0 : (r.d[faceAxis] > 0 ? -1 : 1);
        result.lodLevel = uint8_t(lodLevel);
        result.steps = steps;
    };

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
            readChildPointer(inner, node.pos, header, j, dag.offsetWords[depth], offset, reflection, attributeOffset);
            const unsigned mirror = node.mirror ^ reflection;
            const uint64_t base = node.base + attributeOffset;
            if (depth + 1 == innerLevels) {  // the child is a 4^3 leaf
                leafStored = leaves[offset];
                if (!keepLeaf(base, unsigned(std::popcount(leafStored)))) { skip = half; break; }
                leafSpatial = dag::reflectBrick(leafStored, mirror);
                leafMirror = mirror;
                leafBase = base;
                inLeaf = true;
                break;
            }
            if (options.lodScale > 0 && double(int64_t(1) << half) <= options.lodScale * t) {
                makeHit(base, half);
                occupied = true;
                skip = half;
                break;
            }
            stack[depth + 1] = {dag.levelStart[depth + 1] + offset, base, mirror};
            ++depth;
        }
        if (inLeaf && !occupied && skip == 0) {
            const unsigned x = unsigned(v[0] & 3), y = unsigned(v[1] & 3), z = unsigned(v[2] & 3);
            if ((leafSpatial >> (x + 4 * y + 16 * z)) & 1u) {
                const unsigned bit = storedBit(x, y, z, leafMirror);
                makeHit(leafBase + uint64_t(std::popcount(leafStored & ((uint64_t(1) << bit) - 1))), 0);
                occupied = true;
            } else {
                // An empty 2^3 quarter of the leaf is skipped whole.
                const unsigned corner = (x & 2u) + 4 * (y & 2u) + 16 * (z & 2u);
                if ((leafSpatial & (uint64_t(0x330033) << corner)) == 0) skip = 1;
            }
        }
        if constexpr (kFirstHitOnly)
            if (occupied) return result;
        pending = occupied;

        // Leave the cube of size 2^skip containing v (empty, or just visited).
        if (++steps > options.maxSteps) return kFirstHitOnly ? RayHit{} : result;
        const int64_t cube = int64_t(1) << skip;
        int64_t lo[3], hi[3];
        double tc[3];
        double tNew = kInf;
        for (int a = 0; a < 3; ++a) {
            lo[a] = v[a] & ~(cube - 1);
            hi[a] = lo[a] + cube - 1;
            // The cube's far face on this axis; it is the voxel's own when v is the last voxel that way.
            if (r.d[a] == 0) tc[a] = kInf;
            else if (r.d[a] > 0) tc[a] = v[a] == hi[a] ? tNext[a] : r.crossing(a, hi[a] + 1);
            else tc[a] = v[a] == lo[a] ? tNext[a] : r.crossing(a, lo[a]);
            tNew = std::min(tNew, tc[a]);
        }
        if constexpr (!kFirstHitOnly)
            if (pending) {
                pending = false;
                if (visit(result, std::min(tNew, tExit))) return result;
            }
        if (!(tNew < tExit)) return kFirstHitOnly ? RayHit{} : result;  // left the root cube or passed tMax
        int64_t next[3];
        crossed = 0;
        for (int a = 0; a < 3; ++a) {
            if (tc[a] == tNew) {
                next[a] = r.d[a] > 0 ? hi[a] + 1 : lo[a] - 1;
                if (next[a] < box.lo[a] || next[a] >= box.hi[a]) return kFirstHitOnly ? RayHit{} : result;
                tNext[a] = r.crossing(a, r.d[a] > 0 ? next[a] + 1 : next[a]);
                crossed |= 1u << a;
            } else if (tNext[a] > tNew) {
                next[a] = v[a];  // no voxel boundary of this axis before tNew
            } else {
                double tIn;
                next[a] = r.d[a] > 0 ? r.voxelAt(a, tNew, v[a], hi[a], tIn, tNext[a]) : r.voxelAt(a, tNew, lo[a], v[a], tIn, tNext[a]);
                if (next[a] != v[a] && tIn == tNew) crossed |= 1u << a;
            }
        }
        // Pop to the deepest stored node that still contains the new voxel.
        const uint64_t changed = uint64_t(next[0] ^ v[0]) | uint64_t(next[1] ^ v[1]) | uint64_t(next[2] ^ v[2]);
        const unsigned keepLog2 = unsigned(std::bit_width(changed));  // nodes of log2 size >= this still contain it
        if (keepLog2 > 2) inLeaf = false;
        if (L - depth < keepLog2) depth = L - keepLog2;
        for (int a = 0; a < 3; ++a) v[a] = next[a];
        t = tNew;
    }
}

} // namespace detail

} // namespace vdbdag::trace
