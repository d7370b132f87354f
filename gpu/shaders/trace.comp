#version 460
// The Vulkan tracer over the compact SSVDAG (gpu/VulkanTracer.h), a port of
// the CPU reference tracer (src/trace/): DagWalk.h in trace_walk.glsl,
// palette lookup in palette_channel.glsl, value decode in trace_values.glsl,
// stored ONV normals in trace_normals.glsl, and here the camera
// (Camera::pixelRay, GridFrame::toCellRay), the surface choice
// (SurfaceHit.cpp) and the shading of CpuRenderer.cpp / Shading.cpp.
//
// Two modes (specialisation constant MODE):
//  - hits:   item i traces cell-space ray i (8 doubles: origin, direction,
//            tMin, tMax) and writes 6 uint64: flags (hit | min(wideSteps,
//            127) << 1 | (faceAxis+1) << 8 | (faceSign+1) << 16 | lodLevel
//            << 24 | steps << 32), voxel xyz,
//            t (bits), entry;
//  - render: items are pixels in 8x8 tiles (one workgroup of 64 per tile:
//            neighbouring rays walk the same nodes); writes 8 floats per
//            pixel: rgb, alpha, depth, normal xyz (MIP: 8 uints, the
//            largest value's double bits low and high, 1 if any box);
//  - primary: the camera rays of render, traced only (the hits of hits
//            mode per pixel): what the benchmark measures.
// Only what the scene has is compiled in: value type, level set, fog,
// colouring, shadows and stored normals are specialisation constants.
//
// Double-precision arithmetic is `precise` wherever the CPU could contract a
// product and a sum, so camera rays, crossing times and shading match the
// CPU tracer bit for bit (exp, for fog, is a polynomial here: ~1e-15).
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_control_flow_attributes : require

#include "dispatch.glsl"
#include "trace_params.glsl"
#define VDBDAG_GLSL 1
#include "src/trace/shading_constants.h"

layout(constant_id = 1) const uint MODE = 0u;          // 0: hits, 1: render, 2: primary
layout(constant_id = 2) const bool LEVEL_SET = false;  // surface = first active voxel with value <= 0
layout(constant_id = 3) const uint VALUE_TYPE = 255u;  // ValueType; 255: no values
layout(constant_id = 4) const bool FOG = false;        // render: emission-absorption
layout(constant_id = 5) const uint COLOURING = 0u;     // ValueColouring: none, scalar, colour, vector
layout(constant_id = 6) const bool SHADOWS = false;    // render: shadow rays
layout(constant_id = 7) const bool ONE_CHUNK_DAG = false;  // inner words and leaves each in one chunk
layout(constant_id = 8) const bool HAS_NORMALS = false;    // render: shade with the stored ONV normals
layout(constant_id = 9) const bool MIP = false;            // render: each pixel's largest value (bits), windowed on the host
layout(constant_id = 10) const bool SLICE = false;         // render: each pixel's voxel on the slice plane (its value's bits), windowed on the host
layout(constant_id = 11) const bool LABELS = false;        // render: each pixel's first voxel whose label is shown (a hit), shaded on the host
layout(constant_id = 12) const bool ISO = false;           // render: each pixel's first crossing of P.iso (a hit and its t), shaded on the host
layout(constant_id = 13) const bool VOLUME = false;        // render: emission-absorption through the transfer function (VolumeRender.cpp)
layout(constant_id = 14) const bool WALK_FP32 = true;      // the walk decides in floats, doubles only where they cannot tell (trace_walk.glsl)

layout(buffer_reference, std430, buffer_reference_align = 8) buffer F64Array { double v[]; };

layout(push_constant, std430) uniform Push {
    uint64_t rays;    // hits: F64Array, 8 per ray; LABELS: I64Array, the labels shown
    uint64_t results; // hits: U64Array, 6 per ray; render: F32Array, 8 per pixel (LABELS: hits, 6 uint64)
    uint64_t counter; // render: U32Array[1], shadow rays cast
    uint itemCount;
    uint labelCount;  // LABELS: the labels shown (0: any but 0 and the background)
} pc;

layout(buffer_reference, std430, buffer_reference_align = 8) buffer I64Array { int64_t v[]; };

// LabelRender.cpp firstLabels' isShown.
bool labelShown(int64_t label) {
    if (pc.labelCount == 0u) return label != 0l && label != P.labelBackground;
    I64Array shown = I64Array(pc.rays);
    for (uint k = 0u; k < pc.labelCount; ++k)
        if (shown.v[k] == label) return true;
    return false;
}

#include "trace_values.glsl"
#include "trace_normals.glsl"
#include "trace_inside.glsl"
#include "trace_walk.glsl"

// SurfaceHit.cpp firstSurfaceHit.
Hit firstSurfaceHit(dvec3 o, dvec3 d, double tMin, double tMax, double ignoreBefore, double lodScale) {
    if (!LEVEL_SET) return walkRay(o, d, tMin < ignoreBefore ? ignoreBefore : tMin, tMax, kVisitFirstHit, 0.0lf, lodScale);
    return walkRay(o, d, tMin, tMax, kVisitZeroCrossing, ignoreBefore, lodScale);
}

void writeHit(uint i, Hit h) {
    U64Array res = U64Array(pc.results);
    const uint w = 6u * i;
    res.v[w] = uint64_t(h.hit ? 1u : 0u) | (uint64_t(uint(h.faceAxis + 1)) << 8) | (uint64_t(uint(h.faceSign + 1)) << 16) |
               (uint64_t(min(h.wideSteps, 127u)) << 1) | (uint64_t(h.lodLevel) << 24) | (uint64_t(h.steps) << 32);
    res.v[w + 1u] = uint64_t(h.voxel.x);
    res.v[w + 2u] = uint64_t(h.voxel.y);
    res.v[w + 3u] = uint64_t(h.voxel.z);
    const uvec2 tb = unpackDouble2x32(h.t);
    res.v[w + 4u] = uint64_t(tb.x) | (uint64_t(tb.y) << 32);
    res.v[w + 5u] = h.entry;
}

void traceOneRay(uint i) {
    F64Array rays = F64Array(pc.rays);
    const uint r = 8u * i;
    const dvec3 o = dvec3(rays.v[r], rays.v[r + 1u], rays.v[r + 2u]);
    const dvec3 d = dvec3(rays.v[r + 3u], rays.v[r + 4u], rays.v[r + 5u]);
    // First hits from tMin as given, negative too (DagTracer::trace; the host
    // clamps a surface query on a grid that is no level set to 0).
    writeHit(i, firstSurfaceHit(o, d, rays.v[r + 6u], rays.v[r + 7u], LEVEL_SET ? 0.0lf : -infinity(), P.lodScale));
}

// ---- shading (Shading.cpp, CpuRenderer.cpp) ----------------------------------


double dot3(dvec3 a, dvec3 b) {
    precise double r = a.x * b.x + a.y * b.y + a.z * b.z;
    return r;
}
dvec3 vec3At(double m[3]) { return dvec3(m[0], m[1], m[2]); }

// glm mat3 (column-major, m[3c + r] = column c, row r) times a vector.
dvec3 matTimes(uint which, dvec3 v) {
    precise dvec3 r;
    for (int row = 0; row < 3; ++row) {
        const double m0 = which == 0u ? P.inverse[row] : P.normalMatrix[row];
        const double m1 = which == 0u ? P.inverse[3 + row] : P.normalMatrix[3 + row];
        const double m2 = which == 0u ? P.inverse[6 + row] : P.normalMatrix[6 + row];
        r[row] = m0 * v.x + m1 * v.y + m2 * v.z;
    }
    return r;
}

// GridFrame::normalToWorld.
dvec3 normalToWorld(dvec3 n) {
    const dvec3 w = matTimes(1u, n);
    const double len = sqrt(dot3(w, w));
    return len > 0.0lf ? w / len : dvec3(0.0lf, 0.0lf, 1.0lf);
}

double clampUnit(double x) { return x < 0.0lf ? 0.0lf : (1.0lf < x ? 1.0lf : x); }
bool finite(double x) { return !isnan(x) && !isinf(x); }

dvec3 mixD(dvec3 x, dvec3 y, double a) {
    precise dvec3 r = x * (1.0lf - a) + y * a;
    return r;
}

// Volume rendering (VolumeRender.cpp): the ray's state, and the transfer
// function (TransferFunction.cpp) with pow, log and exp in double.
double gVolTransmittance, gVolFirstHit, gVolPerVoxel;
dvec3 gVolSum, gVolDir;

// log(x) for x > 0 normal: x = m 2^k, m in [sqrt(1/2), sqrt(2)), log m = 2 atanh(s), s = (m-1)/(m+1).
double logDouble(double x) {
    int k;
    double m = frexp(x, k);  // [0.5, 1)
    if (m < 0.70710678118654752lf) {
        m = 2.0lf * m;
        k -= 1;
    }
    precise double s = (m - 1.0lf) / (m + 1.0lf);
    precise double s2 = s * s;
    precise double sum = 0.0lf;
    for (int n = 25; n >= 1; n -= 2) sum = sum * s2 + 1.0lf / double(n);
    precise double r = 2.0lf * s * sum + double(k) * 0.69314718055994530942lf;
    return r;
}
// pow(b, e) for 0 <= b <= 1, e >= 0 (1 - opacity, a length in voxels).
double powUnit(double b, double e) {
    if (e == 0.0lf || b == 1.0lf) return 1.0lf;
    if (!(b > 0.0lf)) return 0.0lf;
    return expDouble(e * logDouble(b));
}

F64Array tfPoints() { return F64Array(pc.rays); }
// TransferFunction.cpp interpolate: the point array at `first`, `n` points of `width` doubles.
double tfInterpolate(uint first, uint n, uint width, uint component, double v) {
    F64Array pts = tfPoints();
    if (!(v > pts.v[first])) return pts.v[first + component];
    if (!(v < pts.v[first + (n - 1u) * width])) return pts.v[first + (n - 1u) * width + component];
    uint upper = 1u;
    while (upper < n - 1u && !(v < pts.v[first + upper * width])) ++upper;
    const double a0 = pts.v[first + (upper - 1u) * width], b0 = pts.v[first + upper * width];
    const double ak = pts.v[first + (upper - 1u) * width + component], bk = pts.v[first + upper * width + component];
    precise double t = b0 > a0 ? (v - a0) / (b0 - a0) : 0.0lf;
    precise double r = ak + (bk - ak) * t;
    return r;
}
double tfOpacity(double v) {
    if (isnan(v)) return 0.0lf;
    if (P.tfOpacityPoints != 0u) return tfInterpolate(4u * P.tfColourPoints, P.tfOpacityPoints, 2u, 1u, v);
    if (!(v > P.tfLow)) return 0.0lf;
    precise double t = (v - P.tfLow) / (P.tfHigh > P.tfLow ? P.tfHigh - P.tfLow : 1.0lf);
    t = t < 1.0lf ? t : 1.0lf;
    precise double r = kMaxOpacity * t * t;
    return r;
}
dvec3 tfColour(double v) {
    if (P.tfColourPoints != 0u) {
        const double x = isnan(v) ? P.tfLow : v;
        return dvec3(tfInterpolate(0u, P.tfColourPoints, 4u, 1u, x), tfInterpolate(0u, P.tfColourPoints, 4u, 2u, x), tfInterpolate(0u, P.tfColourPoints, 4u, 3u, x));
    }
    precise double t = (v - P.tfLow) / (P.tfHigh > P.tfLow ? P.tfHigh - P.tfLow : 1.0lf);
    t = clampUnit(t);
    const dvec3 dark = dvec3(0.45lf, 0.12lf, 0.06lf), ivory = dvec3(0.95lf, 0.90lf, 0.78lf);
    precise dvec3 r = dark + (ivory - dark) * sqrt(t);
    return r;
}
// ValueGradient.cpp valueGradient: central differences of the stored values, normalised; false where none.
bool valueGradientAt(i64vec3 voxel, double centre, out dvec3 g) {
    g = dvec3(0.0lf);
    for (int a = 0; a < 3; ++a) {
        i64vec3 plus = voxel, minus = voxel;
        plus[a] += 1l;
        minus[a] -= 1l;
        uint64_t pe, me;
        const bool p = findVoxel(plus, pe), m = findVoxel(minus, me);
        if (p && m) g[a] = (valueAsDoubles(pe).x - valueAsDoubles(me).x) * 0.5lf;
        else if (p) g[a] = valueAsDoubles(pe).x - centre;
        else if (m) g[a] = centre - valueAsDoubles(me).x;
    }
    const double len = sqrt(dot3(g, g));
    if (!(len > 0.0lf) || !finite(len)) return false;
    g = g / len;
    return true;
}
bool visitVolume(Hit box, double tLeave) {
    const double v = valueAsDoubles(box.entry).x;
    const double a = tfOpacity(v);
    if (a <= 0.0lf) return false;
    precise double alpha = 1.0lf - powUnit(1.0lf - a, (tLeave - box.t) / gVolPerVoxel);
    if (!(alpha > 0.0lf)) return false;
    if (gVolFirstHit < 0.0lf) gVolFirstHit = box.t;
    double lit = 1.0lf;
    dvec3 g;
    if (alpha > 0.01lf && valueGradientAt(box.voxel, v, g)) {  // lit as a surface facing the viewer (Shading.cpp facingNormal)
        dvec3 normal = normalToWorld(-g);
        if (dot3(normal, gVolDir) > 0.0lf) normal = -normal;
        const double lambert = dot3(normal, vec3At(P.light));
        precise double l = kAmbient + (1.0lf - kAmbient) * (0.0lf < lambert ? lambert : 0.0lf);
        lit = l;
    }
    precise dvec3 add = gVolTransmittance * alpha * lit * tfColour(v);
    gVolSum = gVolSum + add;
    gVolTransmittance *= 1.0lf - alpha;
    return gVolTransmittance < 0.02lf;
}

// Shading.cpp baseColour.
dvec3 baseColour(uint64_t entry) {
    if (COLOURING == 1u) {
        const double v = valueAsDoubles(entry).x;
        double s = (v - P.valueMin) / (P.valueMax - P.valueMin);
        s = finite(s) ? clampUnit(s) : 0.0lf;
        return s < 0.5lf ? mixD(kCoolRgb, kMidRgb, s * 2.0lf) : mixD(kMidRgb, kWarmRgb, s * 2.0lf - 1.0lf);
    }
    if (COLOURING == 2u) {
        const dvec3 c = valueAsDoubles(entry);
        const double scale = VALUE_TYPE == kValueVec3I ? 1.0lf / 255.0lf : 1.0lf;
        dvec3 o;
        for (int a = 0; a < 3; ++a) o[a] = finite(c[a]) ? clampUnit(c[a] * scale) : 0.0lf;
        return o;
    }
    if (COLOURING == 3u) {
        const dvec3 c = valueAsDoubles(entry);
        const double len = sqrt(dot3(c, c));
        if (!(len > 0.0lf) || !finite(len)) return dvec3(0.5lf);
        return dvec3(0.5lf) + (0.5lf * c) / len;
    }
    return kMaterialRgb;
}

// CpuRenderer.cpp levelSetGradient: central differences of the stored values.
bool levelSetGradient(Hit hit, out dvec3 g) {
    const double centre = valueAsDoubles(hit.entry).x;
    g = dvec3(0.0lf);
    for (int a = 0; a < 3; ++a) {
        i64vec3 plus = hit.voxel, minus = hit.voxel;
        plus[a] += 1l;
        minus[a] -= 1l;
        uint64_t pa, ma;
        const bool p = findVoxel(plus, pa), m = findVoxel(minus, ma);
        if (p && m) g[a] = (valueAsDoubles(pa).x - valueAsDoubles(ma).x) * 0.5lf;
        else if (p) g[a] = valueAsDoubles(pa).x - centre;
        else if (m) g[a] = centre - valueAsDoubles(ma).x;
    }
    const double len = sqrt(dot3(g, g));
    if (!(len > 0.0lf) || !finite(len)) return false;
    g = g / len;
    return true;
}

// Pixel of item i: 8x8 tiles, one per workgroup of 64 (false past the
// image); within a tile, each run of 8 items (a subgroup on lavapipe, and a
// quarter of a 32-wide GPU warp) is a 4x2 block, whose rays stay closer
// together than a row of 8 and so diverge less.
bool pixelOf(uint i, out uint px, out uint py) {
    const uint tile = i >> 6, within = i & 63u;
    px = (tile % P.tilesX) * 8u + ((within & 3u) | ((within >> 1) & 4u));
    py = (tile / P.tilesX) * 8u + (((within >> 2) & 1u) | ((within >> 3) & 6u));
    return px < P.width && py < P.height;
}

// Camera::pixelRay and GridFrame::toCellRay: the world direction and the cell-space ray.
void cameraRay(uint px, uint py, out dvec3 dir, out dvec3 o, out dvec3 d) {
    precise double u = ((double(px) + 0.5lf) / double(P.width) * 2.0lf - 1.0lf) * P.halfWidth;
    precise double v = (1.0lf - (double(py) + 0.5lf) / double(P.height) * 2.0lf) * P.halfHeight;
    precise dvec3 sum = vec3At(P.forward) + u * vec3At(P.right) + v * vec3At(P.trueUp);
    const double inv = 1.0lf / sqrt(dot3(sum, sum));
    dir = sum * inv;
    o = vec3At(P.eyeCell);
    d = matTimes(0u, dir);
}

const double kCameraTMax = 1e300lf;  // GridFrame::toCellRay's default

// MODE 2: primary rays only, the hit per pixel as in hits mode.
void tracePrimary(uint i) {
    uint px, py;
    if (!pixelOf(i, px, py)) return;
    dvec3 dir, o, d;
    cameraRay(px, py, dir, o, d);
    writeHit(py * P.width + px, firstSurfaceHit(o, d, 0.0lf, kCameraTMax, 0.0lf, P.lodScale));
}

void renderPixel(uint i) {
    uint px, py;
    if (!pixelOf(i, px, py)) return;
    const uint pixel = py * P.width + px;
    dvec3 dir, o, d;
    cameraRay(px, py, dir, o, d);
    const double tMax = kCameraTMax;

    dvec3 colour = vec3At(P.background);
    float alpha = 0.0, depth = uintBitsToFloat(0x7F800000u);
    vec3 normalOut = vec3(0.0);
    if (VOLUME) {  // every occupied box until the light is spent, no level of detail
        gVolTransmittance = 1.0lf;
        gVolFirstHit = -1.0lf;
        gVolSum = dvec3(0.0lf);
        gVolDir = dir;
        gVolPerVoxel = 1.0lf / sqrt(dot3(d, d));
        walkRay(o, d, 0.0lf, tMax, kVisitVolume, 0.0lf, 0.0lf);
        precise dvec3 c = gVolSum + gVolTransmittance * vec3At(P.background);
        F32Array res = F32Array(pc.results);
        const uint w = 8u * pixel;
        res.v[w] = float(c.x);
        res.v[w + 1u] = float(c.y);
        res.v[w + 2u] = float(c.z);
        res.v[w + 3u] = float(1.0lf - gVolTransmittance);
        res.v[w + 4u] = gVolFirstHit >= 0.0lf ? float(gVolFirstHit) : uintBitsToFloat(0x7F800000u);
        res.v[w + 5u] = 0.0;
        res.v[w + 6u] = 0.0;
        res.v[w + 7u] = 0.0;
        return;
    }
    if (ISO) {  // every occupied box until the first crossing, no level of detail (PixelSegments.h)
        gIsoValue = packDouble2x32(uvec2(0u, 0x7FF80000u));  // NaN: no box before
        gIsoCentre = 0.0lf;
        gIsoLeave = -1.0lf;
        gIsoT = 0.0lf;
        writeHit(pixel, walkRay(o, d, 0.0lf, tMax, kVisitIso, 0.0lf, 0.0lf));
        const uvec2 tb = unpackDouble2x32(gIsoT);  // after every pixel's hit: the crossing's t
        U32Array bits = U32Array(pc.results);
        const uint at = 12u * P.width * P.height + 2u * pixel;
        bits.v[at] = tb.x;
        bits.v[at + 1u] = tb.y;
        return;
    }
    if (LABELS) {  // every occupied box until a shown label, no level of detail (PixelSegments.h)
        writeHit(pixel, walkRay(o, d, 0.0lf, tMax, kVisitLabel, 0.0lf, 0.0lf));
        return;
    }
    if (SLICE) {  // SliceView.cpp sliceValues: the voxel where the ray meets the plane through the voxel centres
        U32Array bits = U32Array(pc.results);
        bits.v[8u * pixel + 2u] = 0u;
        const uint a = P.sliceAxis;
        if (d[a] == 0.0lf) return;
        precise double t = (double(P.sliceIndex) + 0.5lf - o[a]) / d[a];
        if (!(t >= 0.0lf) || isinf(t)) return;
        i64vec3 voxel;
        for (uint k = 0u; k < 3u; ++k) {
            precise double c = k == a ? double(P.sliceIndex) : floor(o[k] + t * d[k]);
            if (!(abs(c) < 4e18lf)) return;  // far outside any grid
            voxel[k] = int64_t(c);
        }
        uint64_t entry;
        if (!findVoxel(voxel, entry)) return;
        const uvec2 m = unpackDouble2x32(valueAsDoubles(entry).x);
        bits.v[8u * pixel] = m.x;
        bits.v[8u * pixel + 1u] = m.y;
        bits.v[8u * pixel + 2u] = 1u;
        return;
    }
    if (MIP) {  // every occupied box, no level of detail (PixelSegments.h)
        gMipAny = false;
        gMipMax = 0.0lf;
        walkRay(o, d, 0.0lf, tMax, kVisitMip, 0.0lf, 0.0lf);
        U32Array bits = U32Array(pc.results);
        const uvec2 m = unpackDouble2x32(gMipMax);
        bits.v[8u * pixel] = m.x;
        bits.v[8u * pixel + 1u] = m.y;
        bits.v[8u * pixel + 2u] = gMipAny ? 1u : 0u;
        return;
    }
    if (FOG) {
        gFogTransmittance = 1.0lf;
        gFogFirstHit = -1.0lf;
        gFogSum = dvec3(0.0lf);
        walkRay(o, d, 0.0lf, tMax, kVisitFog, 0.0lf, P.lodScale);
        precise dvec3 c = gFogSum + gFogTransmittance * vec3At(P.background);
        colour = c;
        alpha = float(1.0lf - gFogTransmittance);
        if (gFogFirstHit >= 0.0lf) depth = float(gFogFirstHit);
    } else {
        const Hit hit = firstSurfaceHit(o, d, 0.0lf, tMax, 0.0lf, P.lodScale);
        if (hit.hit) {
            // CpuRenderer.cpp's precedence: the stored normal, else the
            // level-set gradient (finest level only), else the entry face.
            dvec3 normal;
            dvec3 g;
            bool oriented = false;  // outward already: not flipped towards the viewer
            bool haveGradient = false;  // a level set's gradient in g (index space)
            if (storedNormal(hit.entry, normal)) {
                oriented = gNormalsOriented;  // world space already (CpuRenderer.cpp storedNormal)
            } else if (LEVEL_SET && hit.lodLevel == 0u && levelSetGradient(hit, g)) {
                normal = normalToWorld(g);
                oriented = true;
                haveGradient = true;
            } else if (hit.faceAxis >= 0) {
                dvec3 n = dvec3(0.0lf);
                n[hit.faceAxis] = double(hit.faceSign);
                normal = normalToWorld(n);
            } else {
                normal = -dir;
            }
            if (dot3(normal, dir) > 0.0lf && !oriented) normal = -normal;
            const double lambertRaw = dot3(normal, vec3At(P.light));
            double lambert = 0.0lf < lambertRaw ? lambertRaw : 0.0lf;
            if (SHADOWS && lambert > 0.0lf && hit.faceAxis >= 0) {
                precise dvec3 so = o + hit.t * d;
                const dvec3 sd = vec3At(P.lightCell);
                const int f = hit.faceAxis;
                so[f] = double(hit.faceSign < 0 ? hit.voxel[f] : hit.voxel[f] + 1l);
                // One shadow ray, one call of the walk (spirv-opt inlines
                // it at every call site: SPIR-V has 4M ids).
                bool castShadow = false;
                double bias = P.shadowBias;
                if (haveGradient) {
                    // CpuRenderer.cpp: off the surface along the gradient.
                    const dvec3 n = g / sqrt(dot3(g, g));
                    so = so + kShadowNormalOffset * n;
                    castShadow = true;
                } else if ((sd[f] > 0.0lf) == (hit.faceSign > 0) && sd[f] != 0.0lf) {
                    castShadow = true;
                    bias = LEVEL_SET ? P.shadowBias : 0.0lf;
                }
                if (castShadow) {
                    atomicAdd(U32Array(pc.counter).v[0], 1u);
                    if (firstSurfaceHit(so, sd, 0.0lf, infinity(), bias, 0.0lf).hit) lambert = 0.0lf;
                }
            }
            precise dvec3 shaded = baseColour(hit.entry) * (kAmbient + (1.0lf - kAmbient) * lambert);
            colour = shaded;
            alpha = 1.0;
            depth = float(hit.t);
            normalOut = vec3(normal);
        }
    }
    F32Array res = F32Array(pc.results);
    const uint w = 8u * pixel;
    res.v[w] = float(colour.x);
    res.v[w + 1u] = float(colour.y);
    res.v[w + 2u] = float(colour.z);
    res.v[w + 3u] = alpha;
    res.v[w + 4u] = depth;
    res.v[w + 5u] = normalOut.x;
    res.v[w + 6u] = normalOut.y;
    res.v[w + 7u] = normalOut.z;
}

void main() {
    const uint i = vdbdagItemIndex();
    if (i >= pc.itemCount) return;
    loadTraceParams();
    loadValueParams();
    loadInsideParams();
    if (MODE == 1u) loadNormalParams();
    if (MODE == 0u) traceOneRay(i);
    else if (MODE == 1u) renderPixel(i);
    else tracePrimary(i);
}
