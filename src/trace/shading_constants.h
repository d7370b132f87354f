// The shading constants of the CPU renderer (src/trace/Shading.h) and the
// Vulkan shader (gpu/shaders/trace.comp, trace_walk.glsl), one source for
// C++ and GLSL (see include/vdbdag/shader_lang.h): both include this file, so
// that the two tracers' pictures agree by construction. A colour is linear
// RGB in hundredths; C++ sees it as double[3], GLSL as a dvec3.
#ifndef VDBDAG_SHADING_CONSTANTS_H
#define VDBDAG_SHADING_CONSTANTS_H

#include "vdbdag/shader_lang.h"

#ifdef VDBDAG_GLSL
#define VDBDAG_RGB(name, r, g, b) const dvec3 name = dvec3(VDBDAG_RATIO(r, 100), VDBDAG_RATIO(g, 100), VDBDAG_RATIO(b, 100))
#else
#define VDBDAG_RGB(name, r, g, b) inline constexpr double name[3] = {VDBDAG_RATIO(r, 100), VDBDAG_RATIO(g, 100), VDBDAG_RATIO(b, 100)}
#endif

VDBDAG_NAMESPACE_BEGIN

VDBDAG_CONST double kAmbient = VDBDAG_RATIO(2, 10);
// Level-set shadow rays skip voxels within this many voxel lengths of their
// start: the narrow band's staircase would otherwise shadow its own surface.
VDBDAG_CONST double kShadowBias = 3.0;
// ... and start this many voxels off the surface along its gradient.
VDBDAG_CONST double kShadowNormalOffset = 1.5;

// Volume rendering: the opacity per voxel length at the ramp's top (TransferFunction.h).
VDBDAG_CONST double kMaxOpacity = VDBDAG_RATIO(35, 100);

VDBDAG_RGB(kMaterialRgb, 80, 78, 74);    // surfaces without value colouring
VDBDAG_RGB(kFogEmissionRgb, 92, 92, 95); // fog's emitted light
// ParaView's "Cool to Warm" colour map, as three stops (scalar colouring).
VDBDAG_RGB(kCoolRgb, 23, 30, 75);
VDBDAG_RGB(kMidRgb, 87, 87, 87);
VDBDAG_RGB(kWarmRgb, 71, 2, 15);

VDBDAG_NAMESPACE_END

#undef VDBDAG_RGB

#endif
