// Octahedral normal vector decode (ONV; Cigolle et al. 2014, Dado et al.
// §4.3; docs/FORMAT.md), one source for C++ and GLSL (see shader_lang.h): a
// k-bit code (two k/2-bit signed normalised fields, u in the low half) back
// to a unit vector. The arithmetic is double (a literal here is exact as a
// float, so GLSL's float literals convert to the same doubles), in one order, every
// product-plus-sum `precise` in GLSL (no FMA; C++ is built without
// contraction), rounded to float at the end, so that the reader, the CPU
// tracer and the shaders give the same bits. decodeOctahedral
// (src/attributes/OctahedralNormal.cpp) and gpu/shaders/trace_normals.glsl
// include it; a shader enables GL_EXT_shader_explicit_arithmetic_types_int64
// first.
#ifndef VDBDAG_NORMAL_ACCESS_H
#define VDBDAG_NORMAL_ACCESS_H

#include "shader_lang.h"

VDBDAG_NAMESPACE_BEGIN

VDBDAG_FN double onvSignNotZero(double v) { return v >= 0.0 ? 1.0 : -1.0; }  // -0.0 counts as positive

// std::clamp(x, -1.0, 1.0).
VDBDAG_FN double onvClampUnit(double x) { return x < -1.0 ? -1.0 : (1.0 < x ? 1.0 : x); }

// The halfBits-bit field at the bottom of `bits`, sign-extended.
VDBDAG_FN int64_t onvField(uint bits, uint halfBits) {
    const uint mask = (1u << halfBits) - 1u;
    const int64_t raw = int64_t(bits & mask);
    return raw >= (int64_t(1) << (halfBits - 1u)) ? raw - (int64_t(1) << halfBits) : raw;
}

// A point (u, v) of the [-1,1]^2 square unfolded onto the octahedron and
// normalised (double; the encoder scores its candidates with it).
VDBDAG_FN void onvUnfold(double u, double v, VDBDAG_OUT(double) x, VDBDAG_OUT(double) y, VDBDAG_OUT(double) z) {
    double dx = u, dy = v;
    VDBDAG_PRECISE double dz = 1.0 - abs(u) - abs(v);
    if (dz < 0.0) {
        VDBDAG_PRECISE double fx = (1.0 - abs(v)) * onvSignNotZero(u);
        VDBDAG_PRECISE double fy = (1.0 - abs(u)) * onvSignNotZero(v);
        dx = fx;
        dy = fy;
    }
    VDBDAG_PRECISE double len2 = dx * dx + dy * dy + dz * dz;
    const double len = sqrt(len2);
    x = dx / len;
    y = dy / len;
    z = dz / len;
}

// Code -> unit vector, k even in [4, 32].
VDBDAG_FN void onvDecode(uint code, uint k, VDBDAG_OUT(float) x, VDBDAG_OUT(float) y, VDBDAG_OUT(float) z) {
    const uint halfBits = k / 2u;
    const double scale = double((uint64_t(1) << (halfBits - 1u)) - uint64_t(1));
    const double u = onvClampUnit(double(onvField(code, halfBits)) / scale);
    const double v = onvClampUnit(double(onvField(code >> halfBits, halfBits)) / scale);
    double dx, dy, dz;
    onvUnfold(u, v, dx, dy, dz);
    x = float(dx);
    y = float(dy);
    z = float(dz);
}

VDBDAG_NAMESPACE_END

#endif
