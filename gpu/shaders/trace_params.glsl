// The parameter block of trace.comp (gpu::TraceParamsGpu in
// gpu/VulkanTracer.cpp, same std430 layout: every 8-byte member first, then
// the 4-byte ones), reached through a buffer device address: the compact DAG
// (src/encoding/CompactDag.cpp layout), the value channel and the ONV normal
// codes (palette channels, palette_channel.glsl) and the camera and shading
// constants.
#ifndef VDBDAG_TRACE_PARAMS_GLSL
#define VDBDAG_TRACE_PARAMS_GLSL

#include "device_array.glsl"
#include "palette_channel.glsl"

const uint kMaxInnerLevels = 40u;  // encoder limit: log2Size <= 40

// A uniform buffer (set 0, binding 0), std430 (uniformBufferStandardLayout):
// every invocation reads the same words, which lavapipe then loads once per
// subgroup, where a buffer-device-address read is a loop over the lanes.
#extension GL_EXT_scalar_block_layout : require
layout(set = 0, binding = 0, std430) uniform TraceParams {
    DeviceArray inner;      // uint16 words, all inner levels
    DeviceArray leaves;     // uint64 4^3 bricks
    PaletteChannel values;  // entryCount 0 when the grid stores none
    PaletteChannel normals; // uint32 ONV codes (NormalChannel::codes); entryCount 0 when the grid stores none
    DeviceArray inside;     // uint64 words of InsideBits (level sets with values); firstChunk 0 otherwise
    int64_t origin[3];      // index coordinate of the root cube's corner
    int64_t boxLo[3];       // occupied box, relative to the root corner
    int64_t boxHi[3];
    uint64_t levelStart[kMaxInnerLevels];
    double lodScale;        // 0: no LOD cut-off
    double valueMin, valueMax;
    // Camera (Camera::pixelRay), precomputed on the host exactly as the CPU does.
    double forward[3], right[3], trueUp[3];
    double halfWidth, halfHeight;
    double eyeCell[3];      // GridFrame::toCellRay(eye).origin
    double inverse[9];      // GridFrame's inverse linear part, glm column-major
    double normalMatrix[9]; // transpose(inverse), glm column-major
    double light[3];        // world direction towards the light
    double lightCell[3];    // the same in cell space (the shadow rays' direction)
    double background[3];
    double shadowBias;      // level sets: boxes entered before this are ignored by shadow rays
    double fogScale;        // densityScale / (valueMax * voxelSize)
    double iso;             // --shading iso: the surface's value
    double tfLow, tfHigh;   // --shading volume: the transfer function's ramp (TransferFunction.h)
    uint64_t offsetWordsPacked[2];  // offsetWords of each level (<= 4), 3 bits per level: levels 0-20, then 21-39
    int64_t sliceIndex;     // --shading slice: the plane's index along sliceAxis
    int64_t labelBackground;  // --shading labels: the grid's background label
    uint log2Size;
    uint rootReflection;
    uint innerLevels;
    uint maxSteps;
    uint width, height, tilesX;
    uint normalBits;        // k of the ONV codes
    uint normalsOriented;   // 1: gradient-sourced normals (outward: not flipped towards the viewer)
    uint sliceAxis;         // 0, 1, 2: x, y, z
    uint tfColourPoints, tfOpacityPoints;  // its control points (at the push constants' `rays`: 4 doubles each, then 2 each)
} P;

#endif
