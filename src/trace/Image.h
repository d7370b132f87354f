// A rendered frame: linear RGB, coverage, world-space depth and normal per
// pixel, row-major with row 0 at the top. Written by vdb_bridge/ImageWriter
// (PNG: sRGB 8-bit colour; EXR: every channel as float).
#pragma once
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace vdbdag::trace {

struct Image {
    int width = 0, height = 0;
    std::vector<float> rgb;     // 3 per pixel, linear
    std::vector<float> alpha;   // 1 where a surface was hit; fog: 1 - transmittance
    std::vector<float> depth;   // world distance from the eye to the first hit; +inf on a miss
    std::vector<float> normal;  // 3 per pixel, world space, unit; 0 on a miss

    void resize(int w, int h) {
        width = w;
        height = h;
        const size_t n = size_t(w) * size_t(h);
        rgb.assign(3 * n, 0.f);
        alpha.assign(n, 0.f);
        depth.assign(n, std::numeric_limits<float>::infinity());
        normal.assign(3 * n, 0.f);
    }
};

} // namespace vdbdag::trace
