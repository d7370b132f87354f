// CPU traversal of the compact SSVDAG; see DagTracer.h for the arithmetic
// contract and CompactDag.cpp for the word layout. Keep in step with
// gpu/shaders/trace.comp.
#include "src/trace/DagTracer.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include <tbb/parallel_for.h>

namespace vdbdag::trace {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr unsigned kMaxLevels = 64;

struct StackEntry {
    uint64_t pos;     // word index of the node's header in dag.inner
    uint64_t base;    // attribute entry of the node's first entry
    unsigned mirror;  // accumulated reflection
};

// The ray in the root cube's frame, with the per-axis crossing times.
struct LocalRay {
    double o[3], d[3];
    // Time at which the ray crosses the plane `boundary` on axis a (d[a] != 0).
    double crossing(int a, int64_t boundary) const { return (double(boundary) - o[a]) / d[a]; }
    // Voxel coordinate on axis a at time t, by the crossing times themselves
    // (DagTracer.h), within [lo, hi].
    int64_t voxelAt(int a, double t, int64_t lo, int64_t hi) const {
        int64_t c;
        if (d[a] == 0) {
            c = int64_t(std::floor(o[a]));
        } else {
            const double p = o[a] + t * d[a];
            if (!(p > double(lo) - 1)) c = lo;          // also NaN
            else if (!(p < double(hi) + 2)) c = hi;
            else c = d[a] > 0 ? int64_t(std::floor(p)) : int64_t(std::ceil(p)) - 1;
            c = std::clamp(c, lo, hi);
            if (d[a] > 0) {  // voxel c spans [crossing(c), crossing(c + 1))
                while (c < hi && crossing(a, c + 1) <= t) ++c;
                while (c > lo && crossing(a, c) > t) --c;
            } else {         // voxel c spans [crossing(c + 1), crossing(c))
                while (c > lo && crossing(a, c) <= t) --c;
                while (c < hi && crossing(a, c + 1) > t) ++c;
            }
        }
        return std::clamp(c, lo, hi);
    }
};

inline unsigned tagWords(unsigned tag) { return tag == 0 ? 0 : tag == 1 ? 1 : 2; }

// Reads stored child slot j of the node at `pos` (whose header is nonzero).
inline void readChildPointer(const uint16_t* inner, uint64_t pos, uint16_t header, unsigned j, unsigned offsetWords,
                             uint64_t& offset, unsigned& reflection, uint64_t& attributeOffset) {
    uint64_t at = pos + 1;
    unsigned before = 0;
    for (unsigned k = 0; k < j; ++k) {
        const unsigned tag = (header >> (2 * k)) & 3u;
        at += tagWords(tag);
        before += tag != 0;
    }
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

// The traversal. With kFirstHitOnly it returns the first occupied box;
// otherwise it calls visit(hit, tLeave) for every occupied box (voxel, tile
// or LOD node) along the ray, in order, until visit returns true.
template <bool kFirstHitOnly, class Visitor>
RayHit walkRay(const encoding::CompactDag& dag, const TraceOptions& options, const Ray& ray, Visitor&& visit) {
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

    // Clip to the root cube [0, size)^3.
    double tEnter = ray.tMin, tExit = ray.tMax;
    int enterAxis = -1;
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0) {
            if (!(r.o[a] >= 0 && r.o[a] < double(size))) return result;
            continue;
        }
        const double t0 = r.crossing(a, r.d[a] > 0 ? 0 : size), t1 = r.crossing(a, r.d[a] > 0 ? size : 0);
        if (t0 > tEnter) { tEnter = t0; enterAxis = a; }
        tExit = std::min(tExit, t1);
    }
    if (!(tEnter < tExit)) return result;

    int64_t v[3];
    for (int a = 0; a < 3; ++a) v[a] = r.voxelAt(a, tEnter, 0, size - 1);
    double t = tEnter;
    // Axes whose voxel boundary the ray crosses exactly at t (an edge or a
    // corner crossing sets several); the hit face is the lowest of them that
    // is also a face of the hit box (a voxel, a tile or an LOD node).
    unsigned crossed = 0;
    if (enterAxis >= 0)
        for (int a = 0; a < 3; ++a)
            if (r.d[a] != 0 && r.crossing(a, r.d[a] > 0 ? v[a] : v[a] + 1) == t) crossed |= 1u << a;

    StackEntry stack[kMaxLevels];
    unsigned depth = 0;
    stack[0] = {0, 0, dag.rootReflection};
    const uint16_t* inner = dag.inner.data();
    const uint64_t* leaves = dag.leaves.data();
    const unsigned innerLevels = unsigned(dag.innerLevelCount());
    uint32_t steps = 0;

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
        // Descend from stack[depth] towards voxel v until an empty cube (of
        // log2 size `skip`) or a hit.
        unsigned skip;
        while (true) {
            const StackEntry& node = stack[depth];
            const unsigned s = L - depth;  // log2 size of this node
            const uint16_t header = inner[node.pos];
            if (header == 0) {  // solid node: an active tile
                makeHit(node.base, s);
                if constexpr (kFirstHitOnly) return result;
                pending = true;
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
                const uint64_t mask = leaves[offset];
                const unsigned bit = storedBit(unsigned(v[0] & 3), unsigned(v[1] & 3), unsigned(v[2] & 3), mirror);
                if ((mask >> bit) & 1u) {
                    makeHit(base + uint64_t(std::popcount(mask & ((uint64_t(1) << bit) - 1))), 0);
                    if constexpr (kFirstHitOnly) return result;
                    pending = true;
                }
                skip = 0;
                break;
            }
            if (options.lodScale > 0 && double(int64_t(1) << half) <= options.lodScale * t) {
                makeHit(base, half);
                if constexpr (kFirstHitOnly) return result;
                pending = true;
                skip = half;
                break;
            }
            stack[depth + 1] = {dag.levelStart[depth + 1] + offset, base, mirror};
            ++depth;
        }

        // Leave the cube of size 2^skip containing v (empty, or just visited).
        if (++steps > options.maxSteps) return kFirstHitOnly ? RayHit{} : result;
        const int64_t cube = int64_t(1) << skip;
        int64_t lo[3], hi[3];
        double tc[3];
        double tNew = kInf;
        for (int a = 0; a < 3; ++a) {
            lo[a] = v[a] & ~(cube - 1);
            hi[a] = lo[a] + cube - 1;
            tc[a] = r.d[a] == 0 ? kInf : r.crossing(a, r.d[a] > 0 ? hi[a] + 1 : lo[a]);
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
            } else {
                next[a] = r.d[a] > 0 ? r.voxelAt(a, tNew, v[a], hi[a]) : r.d[a] < 0 ? r.voxelAt(a, tNew, lo[a], v[a]) : v[a];
            }
            if (next[a] < 0 || next[a] >= size) return kFirstHitOnly ? RayHit{} : result;
            if (next[a] != v[a] && (tc[a] == tNew || r.crossing(a, r.d[a] > 0 ? next[a] : next[a] + 1) == tNew)) crossed |= 1u << a;
        }
        // Pop to the deepest stored node that still contains the new voxel.
        const uint64_t changed = uint64_t(next[0] ^ v[0]) | uint64_t(next[1] ^ v[1]) | uint64_t(next[2] ^ v[2]);
        const unsigned keepLog2 = unsigned(std::bit_width(changed));  // nodes of log2 size >= this still contain it
        if (L - depth < keepLog2) depth = L - keepLog2;
        for (int a = 0; a < 3; ++a) v[a] = next[a];
        t = tNew;
    }
}

} // namespace

DagTracer::DagTracer(const encoding::CompactDag& dag, TraceOptions options) : dag_(dag), options_(options) {}

RayHit DagTracer::trace(const Ray& ray) const {
    return walkRay<true>(dag_, options_, ray, [](const RayHit&, double) { return true; });
}

void DagTracer::forEachSegment(const Ray& ray, const SegmentVisitor& visit) const {
    walkRay<false>(dag_, options_, ray, visit);
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
    for (unsigned depth = 0;; ++depth) {
        const uint16_t header = dag.inner[pos];
        if (header == 0) return base;
        const unsigned half = dag.log2Size - depth - 1;
        const unsigned p = unsigned((v[0] >> half) & 1) | unsigned((v[1] >> half) & 1) << 1 | unsigned((v[2] >> half) & 1) << 2;
        const unsigned j = p ^ mirror;
        if (((header >> (2 * j)) & 3u) == 0) return std::nullopt;
        uint64_t offset, attributeOffset;
        unsigned reflection;
        readChildPointer(dag.inner.data(), pos, header, j, dag.offsetWords[depth], offset, reflection, attributeOffset);
        mirror ^= reflection;
        base += attributeOffset;
        if (depth + 1 == innerLevels) {
            const uint64_t mask = dag.leaves[offset];
            const unsigned bit = storedBit(unsigned(v[0] & 3), unsigned(v[1] & 3), unsigned(v[2] & 3), mirror);
            if (!((mask >> bit) & 1u)) return std::nullopt;
            return base + uint64_t(std::popcount(mask & ((uint64_t(1) << bit) - 1)));
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
