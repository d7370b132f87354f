// decodeOctahedral (src/attributes/OctahedralNormal.cpp) in GLSL: a k-bit
// octahedral normal vector code (two k/2-bit signed normalised fields, x in
// the low half) back to a unit vector. The same double arithmetic in the same
// order as the CPU (every product-plus-sum `precise`: no FMA), rounded to
// float at the end as the CPU returns it, so the result is bit-identical.
#ifndef VDBDAG_OCTAHEDRAL_NORMAL_GLSL
#define VDBDAG_OCTAHEDRAL_NORMAL_GLSL

#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

double onvSignNotZero(double v) { return v >= 0.0lf ? 1.0lf : -1.0lf; }  // -0.0 counts as positive

// OctahedralNormal.cpp unfold: a point of the [-1,1]^2 square -> unit vector.
dvec3 onvUnfold(double u, double v) {
    double x = u, y = v;
    precise double z = 1.0lf - abs(u) - abs(v);
    if (z < 0.0lf) {
        precise double fx = (1.0lf - abs(v)) * onvSignNotZero(u);
        precise double fy = (1.0lf - abs(u)) * onvSignNotZero(v);
        x = fx;
        y = fy;
    }
    precise double len2 = x * x + y * y + z * z;
    const double len = sqrt(len2);
    return dvec3(x / len, y / len, z / len);
}

// std::clamp(x, -1.0, 1.0).
double onvClampUnit(double x) { return x < -1.0lf ? -1.0lf : (1.0lf < x ? 1.0lf : x); }

// The halfBits-bit field at the bottom of `bits`, sign-extended.
int64_t onvField(uint bits, uint halfBits) {
    const uint mask = (1u << halfBits) - 1u;
    const int64_t raw = int64_t(bits & mask);
    return raw >= (int64_t(1) << (halfBits - 1u)) ? raw - (int64_t(1) << halfBits) : raw;
}

// decodeOctahedral(code, k), k even in [4, 32].
vec3 decodeOctahedral(uint code, uint k) {
    const uint halfBits = k / 2u;
    const double scale = double((uint64_t(1) << (halfBits - 1u)) - 1ul);
    const double u = onvClampUnit(double(onvField(code, halfBits)) / scale);
    const double v = onvClampUnit(double(onvField(code >> halfBits, halfBits)) / scale);
    const dvec3 d = onvUnfold(u, v);
    return vec3(float(d.x), float(d.y), float(d.z));
}

#endif
