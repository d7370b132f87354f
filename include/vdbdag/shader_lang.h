// The language layer of the headers that compile both as C++ and as GLSL
// (dag_access.h, palette_access.h; the PNanoVDB approach): GLSL's types,
// qualifiers and built-ins spelled so that one function body is valid in
// both. A shader defines VDBDAG_GLSL before including them; C++ includes
// them as they are, and their functions live in namespace vdbdag::access.
#ifndef VDBDAG_SHADER_LANG_H
#define VDBDAG_SHADER_LANG_H

#ifdef VDBDAG_GLSL
#define VDBDAG_OUT(T) out T
#define VDBDAG_INOUT(T) inout T
#define VDBDAG_FN
#define VDBDAG_PURE
#define VDBDAG_CONST const
// A double constant as a ratio of integer literals: glslang cannot paste
// the `lf` suffix onto a number, and a plain literal is a float in GLSL.
#define VDBDAG_RATIO(n, d) (double(n) / double(d))
#define VDBDAG_PRECISE precise
#define VDBDAG_NAMESPACE_BEGIN
#define VDBDAG_NAMESPACE_END
#else
#include <bit>
#include <cmath>
#include <cstdint>
#define VDBDAG_OUT(T) T&
#define VDBDAG_INOUT(T) T&
#define VDBDAG_FN inline
#define VDBDAG_PURE constexpr
#define VDBDAG_CONST inline constexpr
#define VDBDAG_RATIO(n, d) (double(n) / double(d))
#define VDBDAG_PRECISE
#define VDBDAG_NAMESPACE_BEGIN namespace vdbdag::access {
#define VDBDAG_NAMESPACE_END }
namespace vdbdag::access {
using uint = unsigned;
constexpr int bitCount(uint x) { return std::popcount(x); }
using std::abs;
using std::sqrt;
} // namespace vdbdag::access
#endif

#endif
