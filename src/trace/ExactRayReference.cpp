// Exact ray/box reference; see ExactRayReference.h. Numbers are dyadic:
// every ray component x is held as the integer X = x * 2^16, and every ray
// parameter as a fraction n / m of 128-bit integers with m > 0.
#include "src/trace/ExactRayReference.h"

#include <bit>
#include <cmath>
#include <algorithm>
#include <optional>

#include "src/util/Error.h"

namespace vdbdag::trace {
namespace {

__extension__ typedef __int128 i128;  // GCC's and clang's 128-bit integer (not ISO C++: -Wpedantic)
constexpr int kScaleBits = 16;
constexpr i128 kScale = i128(1) << kScaleBits;

struct Fraction {
    i128 n, m;  // n / m, m > 0
};
bool less(const Fraction& a, const Fraction& b) { return a.n * b.m < b.n * a.m; }

std::optional<int64_t> scaled(double x) {
    if (!std::isfinite(x) || std::fabs(x) >= std::ldexp(1.0, 40)) return std::nullopt;
    const double s = std::ldexp(x, kScaleBits);
    if (s != std::floor(s)) return std::nullopt;
    return int64_t(s);
}

i128 floorDiv(i128 a, i128 b) {  // b > 0
    i128 q = a / b;
    if ((a % b != 0) && (a < 0)) --q;
    return q;
}

} // namespace

ExactRayReference::ExactRayReference(const encoding::CompactDag& dag, size_t maxBoxes) {
    encoding::visitInAttributeOrder(
        dag,
        [&](const encoding::BrickInstance& b) {
            const uint64_t spatial = b.spatialMask();
            // Attribute entries follow the stored bit order; map spatial bits to them.
            for (unsigned bit = 0; bit < 64; ++bit) {
                if (!((spatial >> bit) & 1u)) continue;
                unsigned x = bit & 3u, y = (bit >> 2) & 3u, z = bit >> 4;
                unsigned sx = (b.mirror & 1u) ? 3 - x : x, sy = (b.mirror & 2u) ? 3 - y : y, sz = (b.mirror & 4u) ? 3 - z : z;
                const unsigned stored = sx + 4 * sy + 16 * sz;
                const uint64_t rank = uint64_t(std::popcount(b.storedMask & ((uint64_t(1) << stored) - 1)));
                if (boxes_.size() >= maxBoxes) throw Error("exact ray reference: more than " + std::to_string(maxBoxes) + " voxels");
                boxes_.push_back({{b.x + x, b.y + y, b.z + z}, 1, b.firstEntry + rank, 0});
            }
        },
        [&](int64_t x, int64_t y, int64_t z, unsigned log2Size, uint64_t entry) {
            boxes_.push_back({{x, y, z}, int64_t(1) << log2Size, entry, log2Size});
        });
}

bool ExactRayReference::representable(const Ray& ray) {
    for (int a = 0; a < 3; ++a)
        if (!scaled(ray.origin[a]) || !scaled(ray.direction[a])) return false;
    return scaled(ray.tMin) && (std::isinf(ray.tMax) ? ray.tMax > 0 : bool(scaled(ray.tMax)));
}

std::vector<RayHit> ExactRayReference::traceAll(const Ray& ray) const {
    if (!representable(ray)) throw Error("exact ray reference: ray components must be multiples of 2^-16 below 2^40");
    i128 O[3], D[3];
    for (int a = 0; a < 3; ++a) { O[a] = *scaled(ray.origin[a]); D[a] = *scaled(ray.direction[a]); }
    const Fraction tMin{*scaled(ray.tMin), kScale};
    const bool bounded = !std::isinf(ray.tMax);
    const Fraction tMax{bounded ? i128(*scaled(ray.tMax)) : 0, kScale};

    struct Found { Fraction t; const Box* box; int axis; };
    std::vector<Found> found;
    for (const Box& box : boxes_) {
        Fraction lo = tMin, hi{0, 0};  // hi.m == 0: unbounded
        int axis = -1;
        bool empty = false;
        for (int a = 0; a < 3 && !empty; ++a) {
            const i128 low = i128(box.min[a]) * kScale, high = i128(box.min[a] + box.size) * kScale;
            if (D[a] == 0) {
                empty = !(O[a] >= low && O[a] < high);
                continue;
            }
            // d > 0: [ (low - O)/D, (high - O)/D );  d < 0: [ (high - O)/D, (low - O)/D )
            Fraction enter, leave;
            if (D[a] > 0) { enter = {low - O[a], D[a]}; leave = {high - O[a], D[a]}; }
            else          { enter = {O[a] - high, -D[a]}; leave = {O[a] - low, -D[a]}; }
            if (less(lo, enter)) { lo = enter; axis = a; }
            if (hi.m == 0 || less(leave, hi)) hi = leave;
        }
        if (empty) continue;
        if (hi.m != 0 && !less(lo, hi)) continue;
        if (bounded && !less(lo, tMax)) continue;
        found.push_back({lo, &box, axis});
    }
    std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) { return less(a.t, b.t); });

    std::vector<RayHit> hits;
    for (const Found& f : found) {
        RayHit hit;
        hit.hit = true;
        hit.t = double(f.t.n) / double(f.t.m);
        hit.attribute = f.box->attribute;
        hit.faceAxis = int8_t(f.axis);
        hit.faceSign = f.axis < 0 ? 0 : (D[f.axis] > 0 ? -1 : 1);
        hit.lodLevel = uint8_t(f.box->log2Size);
        for (int a = 0; a < 3; ++a) {
            if (f.box->size == 1) { hit.voxel[a] = f.box->min[a]; continue; }
            // Position * 2^16 * m = O * m + n * D; voxel per the face convention.
            const i128 num = O[a] * f.t.m + f.t.n * D[a], den = kScale * f.t.m;
            i128 c = D[a] < 0 ? -floorDiv(-num, den) - 1 : floorDiv(num, den);  // ceil(x) - 1 = -floor(-x) - 1
            c = std::max<i128>(f.box->min[a], std::min<i128>(c, f.box->min[a] + f.box->size - 1));
            hit.voxel[a] = int64_t(c);
        }
        hits.push_back(hit);
    }
    return hits;
}

RayHit ExactRayReference::trace(const Ray& ray) const {
    std::vector<RayHit> hits = traceAll(ray);
    return hits.empty() ? RayHit{} : hits.front();
}

std::optional<uint64_t> ExactRayReference::find(const std::array<int64_t, 3>& voxel) const {
    for (const Box& box : boxes_) {
        bool inside = true;
        for (int a = 0; a < 3; ++a) inside = inside && voxel[a] >= box.min[a] && voxel[a] < box.min[a] + box.size;
        if (inside) return box.attribute;
    }
    return std::nullopt;
}

} // namespace vdbdag::trace
