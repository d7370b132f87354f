// vdbdag_make_ct_phantom OUT_PREFIX [--dims X Y Z] [--seed N]
// A Christmas-tree-scale, CT-like phantom for the dense-scan pipeline
// (issue 5): 12-bit values in 16-bit little-endian words, written as
// OUT_PREFIX.raw plus a detached NRRD header OUT_PREFIX.nhdr. Default
// 512x512x999 (about 262M samples, 524 MB), as the real tree CT of Dado et al.
// §5.6 (not downloadable here).
//
// Content (sizes scale with the dims): a pot filled with soil, a trunk, ~60
// whorls of branches spiralling up a cone, thin needles in pairs along every
// branch (partial-volume edges, ~1 voxel thick: the fine structure), a few
// dense ornaments, and scanner noise everywhere (Gaussian, sigma 22 in air
// around level 60, more in the object). Deterministic: a fixed seed gives
// the same bytes on every machine and thread count (the noise of slice z uses
// its own generator seeded from (seed, z); geometry is drawn serially).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

namespace {

struct Rng {  // splitmix64: tiny, fast and identical everywhere
    uint64_t s;
    uint64_t next() {
        uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }
    // Approximately normal (Irwin-Hall of 4), mean 0, sd 1.
    double gauss() { return (uniform() + uniform() + uniform() + uniform() - 2.0) * std::sqrt(3.0); }
};

// The slices [z0, z0 + nz) of the volume, rendered one slab at a time so a
// 2048x2048x1024 phantom needs a few hundred MB, not 26 GB.
struct Slab {
    int nx, ny, z0, nz;
    std::vector<float> density;  // noise-free object intensity above air (0 = air)
    float& at(int x, int y, int z) { return density[(size_t(z - z0) * size_t(ny) + size_t(y)) * size_t(nx) + size_t(x)]; }
};

struct Vec {
    double x, y, z;
};
Vec operator+(Vec a, Vec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec operator-(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec operator*(Vec a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// The t in [0, 1] where |p0.c + t d.c - value| <= reach, as [lo, hi] (empty: lo > hi).
void clipAxis(double p0, double d, double value, double reach, double& lo, double& hi) {
    if (std::abs(d) < 1e-12) {
        if (std::abs(p0 - value) > reach) lo = 1, hi = 0;
        return;
    }
    double a = (value - reach - p0) / d, b = (value + reach - p0) / d;
    if (a > b) std::swap(a, b);
    lo = std::max(lo, a);
    hi = std::min(hi, b);
}

// A capsule (segment p0-p1, radius r) with a one-voxel partial-volume edge,
// composited with max so overlaps do not add up (so the order of shapes and
// slabs does not matter). Each row (y, z) visits only the x range where the
// part of the segment within r + 1 of the row can reach: every voxel it may
// cover, far fewer than the segment's bounding box.
struct Capsule {
    Vec p0, p1;
    double r;
    float value;
    void draw(Slab& v) const {
        const Vec d = p1 - p0;
        const double len2 = std::max(dot(d, d), 1e-12), reach = r + 1;
        const int z0 = std::max(v.z0, int(std::floor(std::min(p0.z, p1.z) - reach))), z1 = std::min(v.z0 + v.nz - 1, int(std::ceil(std::max(p0.z, p1.z) + reach)));
        const int y0 = std::max(0, int(std::floor(std::min(p0.y, p1.y) - reach))), y1 = std::min(v.ny - 1, int(std::ceil(std::max(p0.y, p1.y) + reach)));
        for (int z = z0; z <= z1; ++z)
            for (int y = y0; y <= y1; ++y) {
                double lo = 0, hi = 1;
                clipAxis(p0.z, d.z, z, reach, lo, hi);
                clipAxis(p0.y, d.y, y, reach, lo, hi);
                if (lo > hi) continue;
                const double xa = p0.x + d.x * lo, xb = p0.x + d.x * hi;
                const int x0 = std::max(0, int(std::floor(std::min(xa, xb) - reach))), x1 = std::min(v.nx - 1, int(std::ceil(std::max(xa, xb) + reach)));
                for (int x = x0; x <= x1; ++x) {
                    const Vec p{double(x), double(y), double(z)};
                    const double t = std::clamp(dot(p - p0, d) / len2, 0.0, 1.0);
                    const Vec q = p - (p0 + d * t);
                    const double dist = std::sqrt(dot(q, q));
                    const double cover = std::clamp(r + 0.5 - dist, 0.0, 1.0);
                    if (cover > 0) v.at(x, y, z) = std::max(v.at(x, y, z), float(cover * value));
                }
            }
    }
};

} // namespace

int main(int argc, char** argv) {
    std::string prefix;
    int nx = 512, ny = 512, nz = 999;
    uint64_t seed = 2017;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--dims" && i + 3 < argc) {
            nx = std::atoi(argv[++i]);
            ny = std::atoi(argv[++i]);
            nz = std::atoi(argv[++i]);
        } else if (a == "--seed" && i + 1 < argc) {
            seed = std::strtoull(argv[++i], nullptr, 10);
        } else if (prefix.empty() && a[0] != '-') {
            prefix = a;
        } else {
            std::fprintf(stderr, "usage: vdbdag_make_ct_phantom OUT_PREFIX [--dims X Y Z] [--seed N]\n");
            return 2;
        }
    }
    if (prefix.empty() || nx < 16 || ny < 16 || nz < 16 || nx > 4096 || ny > 4096 || nz > 4096) {
        std::fprintf(stderr, "usage: vdbdag_make_ct_phantom OUT_PREFIX [--dims X Y Z] [--seed N] (each dim 16..4096)\n");
        return 2;
    }
    // The shapes first (drawn serially from one generator), then the
    // volume slab by slab.
    std::vector<Capsule> shapes;
    auto capsule = [&](Vec p0, Vec p1, double r, float value) { shapes.push_back({p0, p1, r, value}); };
    Rng geo{seed};
    const double cx = nx / 2.0, cy = ny / 2.0, s = std::min(nx, ny) / 512.0;  // scale: 1 at the tree's size

    // Trunk.
    capsule({cx, cy, nz * 0.04}, {cx, cy, nz * 0.96}, 11 * s, 1500.0f);
    // Whorls of branches on a cone, needles in pairs along each branch.
    const int whorls = std::max(4, int(60 * nz / 999.0));
    const double golden = 2.399963229728653;
    int branchCount = 0, needleCount = 0;
    for (int w = 0; w < whorls; ++w) {
        const double h = 0.16 + 0.78 * w / double(whorls);  // relative height
        const double zc = nz * h;
        const double length = std::min(nx, ny) * 0.44 * (1.0 - h) + 12 * s;
        const int n = 7 + int(geo.uniform() * 5);
        for (int b = 0; b < n; ++b) {
            const double angle = w * golden + b * 2 * M_PI / n + geo.uniform() * 0.3;
            const double rise = 0.15 + geo.uniform() * 0.25;  // upward tilt
            const Vec dir{std::cos(angle), std::sin(angle), rise};
            const double dl = std::sqrt(dot(dir, dir));
            const Vec u = dir * (1 / dl);
            const Vec p0{cx, cy, zc};
            const Vec p1 = p0 + u * length;
            capsule(p0, p1, 2.6 * s, 1150.0f);
            ++branchCount;
            // Needles: every ~2.5 voxels along the branch, two per station,
            // splayed sideways and forwards.
            const Vec side{-std::sin(angle), std::cos(angle), 0};
            for (double t = 10 * s; t < length; t += 2.5 * s) {
                const Vec base = p0 + u * t;
                for (int k = 0; k < 2; ++k) {
                    const double sgn = k ? 1.0 : -1.0;
                    const double nl = (9 + geo.uniform() * 5) * s;
                    const Vec nd = side * (sgn * 0.8) + u * 0.45 + Vec{0, 0, (geo.uniform() - 0.3) * 0.6};
                    const double nn = std::sqrt(dot(nd, nd));
                    capsule(base, base + nd * (nl / nn), 0.55, 900.0f);
                    ++needleCount;
                }
            }
        }
    }
    // Ornaments: dense (metal-like) balls hanging near branch tips.
    for (int o = 0; o < 24; ++o) {
        const double h = 0.2 + 0.65 * geo.uniform();
        const double angle = geo.uniform() * 2 * M_PI;
        const double reach = std::min(nx, ny) * 0.40 * (1.0 - h);
        const Vec c{cx + std::cos(angle) * reach, cy + std::sin(angle) * reach, nz * h - 8 * s};
        capsule(c, c, 7 * s, 3900.0f);
    }

    const double potTop = nz * 0.12, potR = std::min(nx, ny) * 0.22;
    const std::filesystem::path rawPath = prefix + ".raw", headerPath = prefix + ".nhdr";
    const std::string tmp = rawPath.string() + ".tmp";
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) {
        std::fprintf(stderr, "vdbdag_make_ct_phantom: cannot write %s\n", tmp.c_str());
        return 1;
    }
    const int slabDepth = std::max(1, int((size_t(32) << 20) / (size_t(nx) * size_t(ny))));  // about 200 MB per slab
    for (int z0 = 0; z0 < nz; z0 += slabDepth) {
        Slab v{nx, ny, z0, std::min(slabDepth, nz - z0), {}};
        v.density.assign(size_t(nx) * size_t(ny) * size_t(v.nz), 0.0f);
        // Pot (a thick shell) filled with soil, then the capsules.
        for (int z = z0; z < std::min(z0 + v.nz, int(potTop)); ++z)
            for (int y = 0; y < ny; ++y)
                for (int x = 0; x < nx; ++x) {
                    const double r = std::hypot(x - cx, y - cy) - potR * (0.85 + 0.15 * z / potTop);
                    if (r > 0.5) continue;
                    v.at(x, y, z) = r > -5 * s ? 2300.0f : (z < potTop - 6 ? 950.0f : 0.0f);
                }
        tbb::parallel_for(z0, z0 + v.nz, [&](int z) {  // slice by slice: the capsules of one slice write only there
            Slab slice{nx, ny, z, 1, {}};
            slice.density.assign(v.density.begin() + long(size_t(z - z0) * size_t(nx) * size_t(ny)), v.density.begin() + long(size_t(z - z0 + 1) * size_t(nx) * size_t(ny)));
            for (const Capsule& c : shapes) c.draw(slice);
            std::copy(slice.density.begin(), slice.density.end(), v.density.begin() + long(size_t(z - z0) * size_t(nx) * size_t(ny)));
        });
        // Noise and quantisation to 12 bits, slice by slice in parallel.
        std::vector<uint16_t> out(v.density.size());
        tbb::parallel_for(z0, z0 + v.nz, [&](int z) {
            Rng noise{seed ^ (0xD1B54A32D192ED03ull * uint64_t(z + 1))};
            const size_t base = size_t(z - z0) * size_t(nx) * size_t(ny);
            for (size_t i = 0; i < size_t(nx) * size_t(ny); ++i) {
                const float d = v.density[base + i];
                const double sigma = 22.0 + 0.02 * d;
                const double value = 60.0 + d + sigma * noise.gauss();
                out[base + i] = uint16_t(std::clamp(std::lround(value), 0l, 4095l));
            }
        });
        if (std::fwrite(out.data(), 2, out.size(), f) != out.size()) {
            std::fclose(f);
            std::fprintf(stderr, "vdbdag_make_ct_phantom: cannot write %s\n", tmp.c_str());
            std::remove(tmp.c_str());
            return 1;
        }
    }
    if (std::fclose(f) != 0) {
        std::fprintf(stderr, "vdbdag_make_ct_phantom: cannot write %s\n", tmp.c_str());
        std::remove(tmp.c_str());
        return 1;
    }
    std::filesystem::rename(tmp, rawPath);
    std::FILE* h = std::fopen(headerPath.c_str(), "w");
    if (!h) return 1;
    std::fprintf(h,
                 "NRRD0004\n# CT-like Christmas-tree phantom (vdbdag_make_ct_phantom, seed %llu): 12-bit values in 16-bit words\n"
                 "type: uint16\ndimension: 3\nsizes: %d %d %d\nspacings: 0.93 0.93 0.5\nendian: little\nencoding: raw\ndata file: %s\n",
                 (unsigned long long)seed, nx, ny, nz, rawPath.filename().c_str());
    std::fclose(h);
    std::printf("%s + %s: %dx%dx%d uint16 (12-bit), %d branches, %d needles\n", headerPath.c_str(), rawPath.filename().c_str(), nx, ny, nz,
                branchCount, needleCount);
    return 0;
}
