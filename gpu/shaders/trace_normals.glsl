// Stored shading normals on the GPU (src/attributes/NormalChannel.h): the
// ONV codes of the grid's normal channel, one per attribute entry (the same
// entry index as the values), looked up in their palette channel with a
// block hint of their own and decoded by include/vdbdag/normal_access.h, as
// NormalChannel::decode does. Needs `P` (TraceParams) and the HAS_NORMALS specialisation constant (render
// pipelines of grids with normals only: nothing of this is compiled in
// otherwise).
#ifndef VDBDAG_TRACE_NORMALS_GLSL
#define VDBDAG_TRACE_NORMALS_GLSL

#include "palette_channel.glsl"
#define VDBDAG_GLSL 1
#include "vdbdag/normal_access.h"

PaletteChannel gNormals;     // private copy, loadNormalParams()
uint gNormalBits;            // k of the ONV codes
bool gNormalsOriented;       // gradient-sourced: outward, never flipped towards the viewer
uint64_t gNormalBlockHint = 0ul;

void loadNormalParams() {
    if (!HAS_NORMALS) return;
    gNormals = P.normals;
    gNormalBits = P.normalBits;
    gNormalsOriented = P.normalsOriented != 0u;
}

// CpuRenderer.cpp storedNormal: entry `index`'s decoded normal (world space:
// vdb_bridge computes it through the grid's transform), as a double vector,
// when the grid has one for it.
bool storedNormal(uint64_t index, out dvec3 n) {
    n = dvec3(0.0lf);
    if (!HAS_NORMALS || index >= gNormals.entryCount) return false;
    bool direct;
    const uint64_t byteOffset = paletteLocate(gNormals, index, gNormalBlockHint, direct);
    const uint code = deviceArrayU32(direct ? gNormals.direct : gNormals.materials, byteOffset >> 2);
    float x, y, z;
    onvDecode(code, gNormalBits, x, y, z);
    n = dvec3(x, y, z);
    return true;
}

#endif
