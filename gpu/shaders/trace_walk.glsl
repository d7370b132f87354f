// The traversal of src/trace/DagWalk.h (walkRay) and DagTracer::find: an
// integer DDA over the compact SSVDAG with a stack of (node, mirror mask,
// entry base) (SSVDAG paper §5, Listing 1; Dado et al. §4.1 for the
// offsets). Every crossing time is (boundary - o) / d in double from an
// exact integer boundary, and every product-plus-sum is `precise` (no
// contraction into an FMA), as the CPU build (-ffp-contract=off on
// src/trace): both tracers walk the same boxes and return the same voxels
// and bit-identical t (tests/unit/test_vulkan_tracer.cpp). With WALK_FP32
// (the default on GPUs) the steps are decided in floats wherever floats
// can tell, with the same outcome (see "The walk in 32 bits" below).
//
// The code is arranged for how lavapipe (llvmpipe) runs a shader, 8 lanes
// of a subgroup in SIMD: both sides of every `if` run, every loop body at
// least once per entry, and a buffer-device-address read is a loop over the
// lanes (~220 instructions per read), while a uniform-buffer read at a
// shared offset is one load. So, unlike DagWalk.h: one copy of makeHit and
// of voxelAt (the axis a variable), the sign of the direction a variable
// instead of a branch, a 4^3 leaf entered once per step after the descent,
// empty voxels inside a leaf crossed by a small inner loop, the current
// node in registers (the private stack read only on a pop), and the
// parameters in a uniform buffer. Instructions per 256x192 zero-crossing
// frame of the bunny (callgrind): 622M before these, 338M after. On a GPU
// they cost little either way.
//
// GLSL has no templates or lambdas: the visitor of the segment walk is a
// `visitKind` argument (constant at every call site, so the optimiser keeps
// only the path it needs): first hit; first box with value <= 0 entered at or
// after `ignoreBefore` (SurfaceHit.cpp); fog emission-absorption (CpuRenderer.cpp),
// whose running state lives in the gFog* globals.
#ifndef VDBDAG_TRACE_WALK_GLSL
#define VDBDAG_TRACE_WALK_GLSL

// Private copies of what the walk reads at every step, made once per
// invocation by loadTraceParams() (P is a uniform buffer: cheap to read,
// but a register is cheaper still).
i64vec3 gRootOrigin, gBoxLo, gBoxHi;
uint gLog2Size, gRootReflection, gInnerLevels, gMaxSteps;
uint64_t gInnerAddress, gLeavesAddress;  // chunk 0 of the DAG arrays
DeviceArray gInner, gLeaves;
uint64_t gOffsetWordsPacked[2];  // offsetWords, 3 bits per level (offsetWordsAt)

void loadTraceParams() {
    gRootOrigin = i64vec3(P.origin[0], P.origin[1], P.origin[2]);
    gBoxLo = i64vec3(P.boxLo[0], P.boxLo[1], P.boxLo[2]);
    gBoxHi = i64vec3(P.boxHi[0], P.boxHi[1], P.boxHi[2]);
    gLog2Size = P.log2Size;
    gRootReflection = P.rootReflection;
    gInnerLevels = P.innerLevels;
    gMaxSteps = P.maxSteps;
    gInner = P.inner;
    gLeaves = P.leaves;
    gInnerAddress = gInner.firstChunk;
    gLeavesAddress = gLeaves.firstChunk;
    gOffsetWordsPacked[0] = P.offsetWordsPacked[0];
    gOffsetWordsPacked[1] = P.offsetWordsPacked[1];
}

// P.offsetWords[depth] without a load: the walk's depth differs between the
// invocations of a subgroup, so an indexed read of the parameter block is a
// gather on every descent.
uint offsetWordsAt(uint depth) {
    return depth < 21u ? uint(gOffsetWordsPacked[0] >> (3u * depth)) & 7u : uint(gOffsetWordsPacked[1] >> (3u * (depth - 21u))) & 7u;
}

// The DAG's words; ONE_CHUNK_DAG (specialisation constant: both arrays fit
// one chunk, the usual case) reads them straight from the chunk's address.
uint innerWord(uint64_t index) {
    if (ONE_CHUNK_DAG) return uint(DeviceArrayU16Ptr(gInnerAddress + index * 2ul).value);
    return deviceArrayU16(gInner, index);
}
uint64_t leafMask(uint64_t index) {
    if (ONE_CHUNK_DAG) return DeviceArrayU64Ptr(gLeavesAddress + index * 8ul).value;
    return deviceArrayU64(gLeaves, index);
}

// The DAG's words are parsed by the one source shared with the CPU
// (include/vdbdag/dag_access.h); the buffer argument is unused (a dummy 0u):
// the words are this invocation's globals.
#define VDBDAG_GLSL 1
#define VDBDAG_INNER_WORD(buf, index) innerWord(index)
#include "vdbdag/dag_access.h"

const uint kVisitFirstHit = 0u, kVisitZeroCrossing = 1u, kVisitFog = 2u, kVisitMip = 3u, kVisitLabel = 4u, kVisitIso = 5u, kVisitVolume = 6u;

struct Hit {
    bool hit;
    i64vec3 voxel;      // index coordinate
    double t;
    uint64_t entry;
    int faceAxis;       // -1: started inside
    int faceSign;
    uint lodLevel;
    uint steps;
    uint wideSteps;     // steps decided in doubles (all of them without WALK_FP32)
};

Hit noHit() { return Hit(false, i64vec3(0), 0.0lf, 0ul, -1, 0, 0u, 0u, 0u); }

double infinity() { return packDouble2x32(uvec2(0u, 0x7FF00000u)); }

// The ray in the root cube's frame (LocalRay).
dvec3 gO, gD;

double crossing(int a, int64_t boundary) { return (double(boundary) - gO[a]) / gD[a]; }

// ---- The walk in 32 bits (WALK_FP32) ----------------------------------------
// GPUs outside the data centre run double precision at 1/32-1/64 of float.
// With WALK_FP32 the walk decides each step from float approximations of
// the crossing times and falls back to the doubles above only where the
// floats cannot tell; every decision is the one the doubles make, so the
// hits (voxel, t, face) are bit for bit those of the fp64 walk and of the
// CPU tracer, which stays in doubles.
//
// Error bound. F = (float(b) - float(o)) / float(d) against the double
// crossing T(b) = (b - o) / d: with the conversions of b, o and d, the
// subtraction and the quotient off by at most 1, 1, 1, 1 and 2.5 units in
// the last place (Vulkan's fp32 division is 2.5 ulp; conversions may
// truncate), |F - T| <= 4.5 2^-23 |F| + (|b| + |o|) 2^-23 / |d| (T's own
// 2^-52 aside). As |b| <= |d| |T| + |o|, that is at most 5.5 2^-23 |F| +
// |o| 2^-22 / |d| for any boundary b, inside the occupied box or not.
// errOf gives |F| 8 2^-23 + gK[a], gK[a] = (|o| + max|b| over the occupied
// box) 2^-21 / |d|: room for the rounding of the comparisons and of errOf
// itself, and gK >= 2^-81 (|d| <= 2^60, the box reaching 1) keeps a
// flushed denormal harmless. A decision "T(x) < T(y)" is taken in floats
// only when Fx + Ex < Fy - Ey; otherwise (near ties, exact ties, a ray whose
// numbers a float cannot hold) the step runs in doubles. (The doubles must
// be correctly rounded on the device, as before: Vulkan promises less.)
// The walk's `steps` (statistics) may differ between the two: a step too
// close to call in a leaf is left to the main loop, which may skip a 2^3
// cube the leaf loop would have crossed voxel by voxel.
vec3 gOf, gDf, gK;  // the ray in floats, and errOf's constant per axis (set per ray by walkRay)
const float kFloatRel = 9.5367431640625e-7;  // 2^-20

float crossF(int a, int64_t boundary) { return (float(boundary) - gOf[a]) / gDf[a]; }
float errOf(float f, int a) { return isinf(f) ? 0.0 : abs(f) * kFloatRel + gK[a]; }
float infinityF() { return uintBitsToFloat(0x7F800000u); }

// The time the walk is at, in doubles, from its integer state: the entry
// crossing of the voxel on the lowest axis crossed, or tEnter if none.
// After a step decided in floats (one axis crossed, surely the first) it
// is bit for bit the fp64 walk's t, which is that same crossing; walkRay
// keeps its own t at the start and after a step in doubles, where several
// axes may cross at once and a crossing at 0 may be +0 on one and -0 on
// another.
double entryTime(i64vec3 v, uint crossed, double tEnter) {
    if (crossed == 0u) return tEnter;
    const int a = findLSB(crossed);
    return crossing(a, gD[a] > 0.0lf ? v[a] : v[a] + 1l);
}

// The crossing through which the ray leaves voxel c on axis a (inf if it never does).
double exitTime(int a, int64_t c) { return gD[a] == 0.0lf ? infinity() : crossing(a, gD[a] > 0.0lf ? c + 1l : c); }

int64_t clamp64(int64_t c, int64_t lo, int64_t hi) { return c < lo ? lo : (hi < c ? hi : c); }

// DagWalk.h voxelAt: the one voxel of [lo, hi] whose [tIn, tOut) holds t
// (or the end of the range), found from the guess floor(o + t d) by one
// boundary per turn in either direction. The CPU corrects the guess in two
// loops per sign instead; the voxel, being unique, is the same, and so are
// its crossing times. Here a branch on the sign would run both sides, and
// every loop at least once: one loop, the sign a variable.
int64_t voxelAt(int a, double t, int64_t lo, int64_t hi, out double tIn, out double tOut) {
    const bool up = gD[a] > 0.0lf;
    precise double p = gO[a] + t * gD[a];
    int64_t c;
    if (!(p > double(lo) - 1.0lf)) c = lo;  // also NaN
    else if (!(p < double(hi) + 2.0lf)) c = hi;
    else c = up ? int64_t(floor(p)) : int64_t(ceil(p)) - 1l;
    c = clamp64(c, lo, hi);
    const int64_t forwardStep = up ? 1l : -1l;
    const int64_t first = up ? lo : hi, last = up ? hi : lo;
    const int64_t exitOffset = up ? 1l : 0l;  // voxel c is left through boundary c + exitOffset, entered through c + 1 - exitOffset
    tIn = crossing(a, c + 1l - exitOffset);
    tOut = crossing(a, c + exitOffset);
    while (true) {
        const bool forward = c != last && tOut <= t;
        const bool back = !forward && c != first && tIn > t;
        if (!forward && !back) break;
        c += forward ? forwardStep : -forwardStep;
        const double crossed = crossing(a, forward ? c + exitOffset : c + 1l - exitOffset);
        if (forward) {
            tIn = tOut;
            tOut = crossed;
        } else {
            tOut = tIn;
            tIn = crossed;
        }
    }
    return c;
}

int64_t voxelAtStart(int a, double t, int64_t lo, int64_t hi) {
    if (gD[a] == 0.0lf) return clamp64(int64_t(floor(gO[a])), lo, hi);
    double tIn, tOut;
    return voxelAt(a, t, lo, hi, tIn, tOut);
}

uint bitWidth64(uint64_t x) {
    const uvec2 h = unpackUint2x32(x);
    return h.y != 0u ? uint(findMSB(h.y)) + 33u : (h.x != 0u ? uint(findMSB(h.x)) + 1u : 0u);
}

// Fog state (CpuRenderer.cpp): transmittance, emitted light, first box entered.
double gFogTransmittance, gFogFirstHit;
dvec3 gFogSum;
// Isosurface (IsoSurface.cpp firstCrossings): the box before on the ray (its
// value, centre and exit), and the crossing's ray parameter.
double gIsoValue, gIsoCentre, gIsoLeave, gIsoT;
// Maximum intensity projection (Projection.cpp maximaAlongRays): the largest
// value met so far, once any box was.
double gMipMax;
bool gMipAny;

// exp(x) in double (GLSL has exp for float only): x = k ln2 + r, |r| <= ln2/2,
// a degree-13 Taylor polynomial, then ldexp. Relative error ~1e-15.
double expDouble(double x) {
    if (!(x > -745.0lf)) return x != x ? x : 0.0lf;
    if (x > 709.0lf) return infinity();
    const double k = floor(x * 1.4426950408889634lf + 0.5lf);
    precise double r = (x - k * 0.693147180369123816490lf) - k * 1.90821492927058770002e-10lf;
    precise double p = 1.0lf / 6227020800.0lf;
    p = p * r + 1.0lf / 479001600.0lf;
    p = p * r + 1.0lf / 39916800.0lf;
    p = p * r + 1.0lf / 3628800.0lf;
    p = p * r + 1.0lf / 362880.0lf;
    p = p * r + 1.0lf / 40320.0lf;
    p = p * r + 1.0lf / 5040.0lf;
    p = p * r + 1.0lf / 720.0lf;
    p = p * r + 1.0lf / 120.0lf;
    p = p * r + 1.0lf / 24.0lf;
    p = p * r + 1.0lf / 6.0lf;
    p = p * r + 0.5lf;
    p = p * r + 1.0lf;
    p = p * r + 1.0lf;
    return ldexp(p, int(k));
}

// Volume rendering's visitor (trace.comp, after the shading helpers it uses).
bool visitVolume(Hit box, double tLeave);

// The visitor of the segment walks; true stops the walk.
// `knownInside`: the walk has tested the box's inside bit already.
bool visitBox(uint visitKind, inout Hit box, double tLeave, double ignoreBefore, inout Hit found, bool knownInside) {
    if (visitKind == kVisitZeroCrossing) {
        if (box.t < ignoreBefore) return false;
        if (!knownInside && (gHasInside ? !insideAt(box.entry) : !(valueAsDoubles(box.entry).x <= 0.0lf))) return false;
        found = box;
        return true;
    }
    if (visitKind == kVisitVolume) return visitVolume(box, tLeave);
    if (visitKind == kVisitIso) {
        const double v = valueAsDoubles(box.entry).x;
        if (!(v >= P.iso)) {  // below, or NaN
            gIsoValue = v;
            gIsoCentre = 0.5lf * (box.t + tLeave);
            gIsoLeave = tLeave;
            return false;
        }
        precise double t = box.t;
        if (gIsoValue < P.iso && gIsoLeave == box.t) {  // touching boxes: between their centres
            precise double centre = 0.5lf * (box.t + tLeave);
            t = gIsoCentre + (P.iso - gIsoValue) / (v - gIsoValue) * (centre - gIsoCentre);
        }
        gIsoT = t;
        found = box;
        return true;
    }
    if (visitKind == kVisitLabel) {  // LabelRender.cpp firstLabels: the first box whose label is shown
        const double v = valueAsDoubles(box.entry).x;
        if (!labelShown(isnan(v) || isinf(v) ? 0l : int64_t(v))) return false;
        found = box;
        return true;
    }
    if (visitKind == kVisitMip) {
        const double v = valueAsDoubles(box.entry).x;
        if (!isnan(v) && (!gMipAny || v > gMipMax)) {
            gMipMax = v;
            gMipAny = true;
        }
        return false;
    }
    // kVisitFog
    if (gFogFirstHit < 0.0lf) gFogFirstHit = box.t;
    const double v = valueAsDoubles(box.entry).x;
    const double density = 0.0lf < v ? v : 0.0lf;
    precise double alpha = 1.0lf - expDouble(-P.fogScale * density * (tLeave - box.t));
    precise dvec3 add = (gFogTransmittance * alpha) * kFogEmissionRgb;
    gFogSum = gFogSum + add;
    gFogTransmittance *= 1.0lf - alpha;
    return gFogTransmittance < 1e-3lf;
}

Hit makeHit(i64vec3 v, uint crossed, double t, uint64_t entry, uint lodLevel, uint steps, uint wideSteps) {
    int faceAxis = -1;
    const int64_t within = (int64_t(1) << lodLevel) - 1l;
    // The lowest crossed axis whose face is also the box's (straight-line:
    // on lavapipe a loop's body runs at least once, whatever its condition).
    for (int a = 2; a >= 0; --a)
        if (((crossed >> a) & 1u) != 0u && (v[a] & within) == (gD[a] > 0.0lf ? 0l : within)) faceAxis = a;
    Hit h;
    h.hit = true;
    h.voxel = v + gRootOrigin;
    h.t = t == 0.0lf ? 0.0lf : t;  // +0.0, as DagWalk.h: which axis a tie of crossings at 0 comes from decides its sign
    h.entry = entry;
    h.faceAxis = faceAxis;
    h.faceSign = faceAxis < 0 ? 0 : (gD[faceAxis] > 0.0lf ? -1 : 1);
    h.lodLevel = lodLevel;
    h.steps = steps;
    h.wideSteps = wideSteps;
    return h;
}

// WALK_FP32: the voxel of [lo, hi] on axis a at the time whose float is tF
// (error eT), as voxelAt finds it, with the float of its exit time; false
// when a comparison is too close to call in floats (or the guess is more
// than a few voxels off). The voxel it returns is entered strictly before
// that time (voxelAt's tIn < t), so the axis is not crossed at it.
bool voxelAtFloat(int a, float tF, float eT, int64_t lo, int64_t hi, out int64_t c, out float tOutF) {
    const bool up = gD[a] > 0.0lf;
    const float p = gOf[a] + tF * gDf[a];
    if (!(p > float(lo) - 1.0)) c = lo;
    else if (!(p < float(hi) + 2.0)) c = hi;
    else c = up ? int64_t(floor(p)) : int64_t(ceil(p)) - 1l;
    c = clamp64(c, lo, hi);
    const int64_t forwardStep = up ? 1l : -1l;
    const int64_t first = up ? lo : hi, last = up ? hi : lo;
    const int64_t exitOffset = up ? 1l : 0l;
    float tInF = crossF(a, c + 1l - exitOffset);
    tOutF = crossF(a, c + exitOffset);
    [[dont_unroll]] for (int turn = 0; turn < 4; ++turn) {
        const float eIn = errOf(tInF, a), eOut = errOf(tOutF, a);
        const bool outBefore = c != last && tOutF + eOut < tF - eT;   // voxelAt moves forward
        const bool outUnsure = c != last && !outBefore && !(tOutF - eOut > tF + eT);
        const bool inAfter = c != first && tInF - eIn > tF + eT;      // voxelAt moves back
        const bool inUnsure = c != first && !inAfter && !(tInF + eIn < tF - eT);
        if (outUnsure || inUnsure) return false;
        if (!outBefore && !inAfter) return true;
        c += outBefore ? forwardStep : -forwardStep;
        tInF = crossF(a, c + 1l - exitOffset);
        tOutF = crossF(a, c + exitOffset);
    }
    return false;
}

// walkRay. kVisitFirstHit returns the first occupied box, kVisitZeroCrossing,
// kVisitLabel and kVisitIso the first box the visitor accepts, kVisitFog,
// kVisitMip and kVisitVolume the last box (unused).
Hit walkRay(dvec3 origin, dvec3 direction, double tMin, double tMax, uint visitKind, double ignoreBefore, double lodScale) {
    const bool firstOnly = visitKind == kVisitFirstHit;
    Hit result = noHit();
    Hit found = noHit();
    if (gLog2Size == 0u) return result;
    for (int a = 0; a < 3; ++a) {
        if (isnan(origin[a]) || isinf(origin[a]) || isnan(direction[a]) || isinf(direction[a])) return result;
        gO[a] = origin[a] - double(gRootOrigin[a]);
        gD[a] = direction[a];
    }
    if (isnan(tMin) || isnan(tMax)) return result;
    const uint L = gLog2Size;

    double tEnter = tMin, tExit = tMax;
    int enterAxis = -1;
    for (int a = 0; a < 3; ++a) {
        if (gD[a] == 0.0lf) {
            if (!(gO[a] >= double(gBoxLo[a]) && gO[a] < double(gBoxHi[a]))) return result;
            continue;
        }
        const double t0 = crossing(a, gD[a] > 0.0lf ? gBoxLo[a] : gBoxHi[a]);
        const double t1 = crossing(a, gD[a] > 0.0lf ? gBoxHi[a] : gBoxLo[a]);
        if (t0 > tEnter) { tEnter = t0; enterAxis = a; }
        tExit = t1 < tExit ? t1 : tExit;
    }
    if (!(tEnter < tExit)) return result;

    i64vec3 v;
    for (int a = 0; a < 3; ++a) v[a] = voxelAtStart(a, tEnter, gBoxLo[a], gBoxHi[a] - 1l);
    double t = tEnter;
    uint crossed = 0u;
    if (enterAxis >= 0)
        for (int a = 0; a < 3; ++a)
            if (gD[a] != 0.0lf && crossing(a, gD[a] > 0.0lf ? v[a] : v[a] + 1l) == t) crossed |= 1u << a;

    dvec3 tNext;  // a vector, not an array: indexed by a varying axis below
    for (int a = 0; a < 3; ++a) tNext[a] = exitTime(a, v[a]);

    // WALK_FP32: the floats of tNext and tExit; t and tNext then hold only
    // where a step ran in doubles (entryTime gives t at a hit). Rays with
    // numbers too large or too small for a float walk in doubles throughout.
    vec3 fNext = vec3(0.0);
    float fExit = 0.0, eExit = 0.0;
    bool useF = WALK_FP32;
    bool tFresh = true;  // t is the walk's time (else entryTime gives it: the last step was in floats)
    if (useF) {
        const double kBig = 1152921504606846976.0lf;  // 2^60
        const double kScale = 1.0lf / 2097152.0lf;      // 2^-21
        for (int a = 0; a < 3; ++a) {
            const double ad = abs(gD[a]);
            const double maxB = double(max(abs(gBoxLo[a]), abs(gBoxHi[a])));
            if (ad != 0.0lf && !(ad >= 1.0lf / kBig && ad <= kBig && abs(gO[a]) <= kBig)) useF = false;
            gOf[a] = float(gO[a]);
            gDf[a] = float(gD[a]);
            gK[a] = ad == 0.0lf ? 0.0 : float((abs(gO[a]) + maxB) / ad * kScale) * 1.0001;
            fNext[a] = float(tNext[a]);
        }
        fExit = float(tExit);
        eExit = isinf(fExit) ? 0.0 : abs(fExit) * kFloatRel;
    }

    // The stack of stored nodes containing v, a node's word position and
    // mirror mask packed in one word (pos | mirror << 61), and the node at
    // `depth` also in registers (node*): the stack is private memory, whose
    // every access is a gather or a scatter, so it is read only on a pop.
    uint64_t stackPosMirror[kMaxInnerLevels];
    uint64_t stackBase[kMaxInnerLevels];
    uint depth = 0u;
    uint64_t nodePos = 0ul, nodeBase = 0ul;
    uint nodeMirror = gRootReflection;
    stackPosMirror[0] = uint64_t(gRootReflection) << 61;
    stackBase[0] = 0ul;
    const uint innerLevels = gInnerLevels;
    uint steps = 0u, wideSteps = 0u;
    bool inLeaf = false;
    uint64_t leafStored = 0ul, leafSpatial = 0ul, leafBase = 0ul;
    uint leafMirror = 0u;
    // Zero crossing with inside bits: the leaf's bits (insideWord); its
    // voxels that are outside are passed as empty, the others as inside.
    const bool insideTest = visitKind == kVisitZeroCrossing && gHasInside;
    uint64_t leafInside = 0ul;
    bool pending = false, pendingInside = false;

    while (true) {
        uint skip = 0u;
        bool occupied = false;
        // The occupied box found (a tile, an LOD node or a leaf voxel): one
        // makeHit below for all three, as lavapipe runs every copy of it.
        uint64_t hitEntry = 0ul;
        uint hitLevel = 0u;
        bool enterLeaf = false;  // the descent reached a 4^3 leaf (at leafOffset, leafMirror, leafBase)
        uint64_t leafOffset = 0ul;
        // The walk's time for the LOD cut-off, once per step (not per level).
        const double tLod = lodScale > 0.0lf ? (tFresh ? t : entryTime(v, crossed, tEnter)) : 0.0lf;
        while (!inLeaf) {
            const uint s = L - depth;
            const uint header = innerWord(nodePos);
            if (header == 0u) {
                hitEntry = nodeBase;
                hitLevel = s;
                occupied = true;
                skip = s;
                break;
            }
            const uint halfLog2 = s - 1u;
            const uint p = uint((v[0] >> halfLog2) & 1l) | (uint((v[1] >> halfLog2) & 1l) << 1) | (uint((v[2] >> halfLog2) & 1l) << 2);
            const uint j = p ^ nodeMirror;
            if (((header >> (2u * j)) & 3u) == 0u) { skip = halfLog2; break; }
            uint64_t offset, attributeOffset;
            uint reflection;
            dagChildPointer(0u, nodePos, header, j, offsetWordsAt(depth), offset, reflection, attributeOffset);
            const uint mirror = nodeMirror ^ reflection;
            const uint64_t base = nodeBase + attributeOffset;
            if (depth + 1u == innerLevels) {  // the child is a 4^3 leaf: entered below, once per step
                enterLeaf = true;
                leafOffset = offset;
                leafMirror = mirror;
                leafBase = base;
                break;
            }
            if (lodScale > 0.0lf && double(int64_t(1) << halfLog2) <= lodScale * tLod) {
                hitEntry = base;
                hitLevel = halfLog2;
                occupied = true;
                skip = halfLog2;
                break;
            }
            nodePos = P.levelStart[depth + 1u] + offset;
            nodeBase = base;
            nodeMirror = mirror;
            ++depth;
            stackPosMirror[depth] = nodePos | (uint64_t(mirror) << 61);
            stackBase[depth] = base;
        }
        if (enterLeaf) {
            // Outside the descent loop, which lavapipe runs at least once per
            // step for the whole subgroup: this then runs once, not per level.
            leafStored = leafMask(leafOffset);
            // A leaf with no inside voxel is empty space to the zero crossing (DagWalk.h keepLeaf).
            if (insideTest) leafInside = insideWord(leafBase, dagPopcount64(leafStored));
            if (insideTest && leafInside == 0ul) {
                skip = L - depth - 1u;
            } else {
                leafSpatial = dagReflectBrick(leafStored, leafMirror);
                inLeaf = true;
            }
        }
        // Inside a leaf, past voxels the walk does not stop at (empty, or
        // outside for the zero crossing) one voxel step per turn of a small
        // loop, the axis a variable, until a voxel to stop at, a tie between
        // axes, the leaf's or the box's end, or tExit: the same voxels, t and
        // faces as the steps of the main loop, whose every turn costs the
        // whole walk on lavapipe. In floats, a step too close to call is
        // left to the main loop as a tie is.
        while (inLeaf && !occupied && skip == 0u) {
            const uint x = uint(v[0] & 3l), y = uint(v[1] & 3l), z = uint(v[2] & 3l);
            if (((leafSpatial >> (x + 4u * y + 16u * z)) & 1ul) != 0ul) {
                if (!insideTest) break;
                const uint rank = dagLeafRank(leafStored, dagStoredBit(x, y, z, leafMirror));
                if (((leafInside >> rank) & 1ul) != 0ul) break;
            }
            int a;
            double tStep = t;
            if (useF) {
                const float fNew = min(fNext[0], min(fNext[1], fNext[2]));
                a = fNext[0] == fNew ? 0 : (fNext[1] == fNew ? 1 : 2);
                const float e = errOf(fNew, a);
                if (!(fNew + e < fExit - eExit)) break;
                const float lead = fNew + e;
                if ((a != 0 && !(lead < fNext[0] - errOf(fNext[0], 0))) || (a != 1 && !(lead < fNext[1] - errOf(fNext[1], 1))) ||
                    (a != 2 && !(lead < fNext[2] - errOf(fNext[2], 2))))
                    break;
            } else {
                const double tNew = min(tNext[0], min(tNext[1], tNext[2]));
                if (!(tNew < tExit)) break;
                a = tNext[0] == tNew ? 0 : (tNext[1] == tNew ? 1 : 2);
                if ((a < 1 && tNext[1] == tNew) || (a < 2 && tNext[2] == tNew)) break;  // a tie: the main loop's step
                tStep = tNew;
            }
            const int64_t nx = gD[a] > 0.0lf ? v[a] + 1l : v[a] - 1l;
            if ((nx >> 2) != (v[a] >> 2) || nx < gBoxLo[a] || nx >= gBoxHi[a]) break;
            if (++steps > gMaxSteps) break;
            if (useF) fNext[a] = crossF(a, gD[a] > 0.0lf ? nx + 1l : nx);
            else tNext[a] = crossing(a, gD[a] > 0.0lf ? nx + 1l : nx);
            v[a] = nx;
            crossed = 1u << a;
            if (useF) {
                tFresh = false;
            } else {
                t = tStep;
                ++wideSteps;
            }
        }
        bool occupiedInside = false;
        if (inLeaf && !occupied && skip == 0u) {
            const uint x = uint(v[0] & 3l), y = uint(v[1] & 3l), z = uint(v[2] & 3l);
            if (((leafSpatial >> (x + 4u * y + 16u * z)) & 1ul) != 0ul) {
                const uint bit = dagStoredBit(x, y, z, leafMirror);
                const uint rank = dagLeafRank(leafStored, bit);
                // An outside voxel would be rejected by the visitor: not passed at all.
                if (!insideTest || ((leafInside >> rank) & 1ul) != 0ul) {
                    hitEntry = leafBase + uint64_t(rank);
                    hitLevel = 0u;
                    occupied = true;
                    occupiedInside = insideTest;
                }
            } else {
                const uint corner = (x & 2u) + 4u * (y & 2u) + 16u * (z & 2u);
                if ((leafSpatial & (uint64_t(0x330033) << corner)) == 0ul) skip = 1u;
            }
        }
        if (occupied) result = makeHit(v, crossed, tFresh ? t : entryTime(v, crossed, tEnter), hitEntry, hitLevel, steps, wideSteps);
        if (firstOnly && occupied) return result;
        pending = occupied;
        pendingInside = occupiedInside;

        if (++steps > gMaxSteps) return firstOnly ? noHit() : found;
        const int64_t cube = int64_t(1) << skip;
        i64vec3 lo, hi;
        for (int a = 0; a < 3; ++a) {
            lo[a] = v[a] & ~(cube - 1l);
            hi[a] = lo[a] + cube - 1l;
        }
        i64vec3 next = v;
        // The step in floats where they can tell (WALK_FP32): the axis that
        // leaves the cube first (am) at fNew, surely alone and surely before
        // or after tExit, and every other axis surely without a boundary
        // before it or with its voxel there found by voxelAtFloat.
        bool stepped = false;
        int am = 0;
        bool after = false;
        vec3 fNextNew = fNext;
        if (useF) {
            vec3 tcF;
            for (int a = 0; a < 3; ++a) {
                const bool up = gD[a] > 0.0lf;
                const float tFar = crossF(a, up ? hi[a] + 1l : lo[a]);
                tcF[a] = gD[a] == 0.0lf ? infinityF() : (v[a] == (up ? hi[a] : lo[a]) ? fNext[a] : tFar);
            }
            const float fNew = min(tcF[0], min(tcF[1], tcF[2]));
            am = tcF[0] == fNew ? 0 : (tcF[1] == fNew ? 1 : 2);
            const float eNew = errOf(fNew, am);
            bool sure = !isinf(fNew);
            for (int a = 0; a < 3; ++a)
                if (a != am && !(fNew + eNew < tcF[a] - errOf(tcF[a], a))) sure = false;
            const bool before = fNew + eNew < fExit - eExit;
            after = fNew - eNew > fExit + eExit;
            if (!before && !after) sure = false;
            if (sure && before) {
                const bool upM = gD[am] > 0.0lf;
                next[am] = upM ? hi[am] + 1l : lo[am] - 1l;
                fNextNew[am] = crossF(am, upM ? next[am] + 1l : next[am]);
                uint unknown = 0u;
                for (int a = 0; a < 3; ++a) {
                    if (a == am || gD[a] == 0.0lf) continue;
                    const float e = errOf(fNext[a], a);
                    if (fNext[a] - e > fNew + eNew) continue;  // stays in v[a]
                    if (fNext[a] + e < fNew - eNew) unknown |= 1u << a;
                    else sure = false;
                }
                while (sure && unknown != 0u) {
                    const int a = findLSB(unknown);
                    unknown &= unknown - 1u;
                    const bool up = gD[a] > 0.0lf;
                    int64_t c;
                    float tOutF;
                    if (!voxelAtFloat(a, fNew, eNew, up ? v[a] : lo[a], up ? hi[a] : v[a], c, tOutF)) sure = false;
                    next[a] = c;
                    fNextNew[a] = tOutF;
                }
            }
            stepped = sure;
            if (!sure) {
                next = v;
                // The doubles of the state, for the step in doubles below.
                for (int a = 0; a < 3; ++a) tNext[a] = exitTime(a, v[a]);
                if (!tFresh) t = entryTime(v, crossed, tEnter);
                tFresh = true;
            }
        }
        dvec3 tc;
        double tNew = infinity();
        if (!stepped) {
            ++wideSteps;
            for (int a = 0; a < 3; ++a) {
                // The cube's far face on this axis (one crossing whatever the
                // sign: both sides of a branch run here); the voxel's own exit
                // when v is the cube's last voxel that way.
                const bool up = gD[a] > 0.0lf;
                const double tFar = crossing(a, up ? hi[a] + 1l : lo[a]);
                tc[a] = gD[a] == 0.0lf ? infinity() : (v[a] == (up ? hi[a] : lo[a]) ? tNext[a] : tFar);
                tNew = tc[a] < tNew ? tc[a] : tNew;
            }
        }
        // The box just left, visited once for both arithmetics (spirv-opt
        // inlines the visitors at every call: SPIR-V has only 4M ids).
        if (!firstOnly && pending) {
            pending = false;
            double tLeave = tExit < tNew ? tExit : tNew;
            if (stepped) tLeave = after ? tExit : crossing(am, gD[am] > 0.0lf ? hi[am] + 1l : lo[am]);
            if (visitBox(visitKind, result, tLeave, ignoreBefore, found, pendingInside)) return found;
        }
        if (stepped) {
            if (after) return firstOnly ? noHit() : found;
            if (next[am] < gBoxLo[am] || next[am] >= gBoxHi[am]) return firstOnly ? noHit() : found;
            fNext = fNextNew;
            crossed = 1u << am;
            tFresh = false;
        } else {
            if (!(tNew < tExit)) return firstOnly ? noHit() : found;
            crossed = 0u;
            uint unknown = 0u;  // axes whose voxel at tNew voxelAt must find
            for (int a = 0; a < 3; ++a) {
                if (tc[a] == tNew) {
                    next[a] = gD[a] > 0.0lf ? hi[a] + 1l : lo[a] - 1l;
                    if (next[a] < gBoxLo[a] || next[a] >= gBoxHi[a]) return firstOnly ? noHit() : found;
                    tNext[a] = crossing(a, gD[a] > 0.0lf ? next[a] + 1l : next[a]);
                    crossed |= 1u << a;
                } else if (!(tNext[a] > tNew)) {
                    unknown |= 1u << a;
                }
            }
            // At most two axes (one at least is crossed), through one copy of
            // voxelAt with the axis as a variable: lavapipe runs every copy of
            // code in the loop for every subgroup, and voxelAt is the costliest.
            while (unknown != 0u) {
                const int a = findLSB(unknown);
                unknown &= unknown - 1u;
                double tIn, tOut;
                // From v forwards to the cube's far end: one call, the range chosen first.
                const bool up = gD[a] > 0.0lf;
                const int64_t c = voxelAt(a, tNew, up ? v[a] : lo[a], up ? hi[a] : v[a], tIn, tOut);
                next[a] = c;
                tNext[a] = tOut;
                if (c != v[a] && tIn == tNew) crossed |= 1u << a;
            }
            t = tNew;
            if (useF)
                for (int a = 0; a < 3; ++a) fNext[a] = float(tNext[a]);
        }
        const uint64_t changed = uint64_t(next[0] ^ v[0]) | uint64_t(next[1] ^ v[1]) | uint64_t(next[2] ^ v[2]);
        const uint keepLog2 = bitWidth64(changed);
        if (keepLog2 > 2u) inLeaf = false;
        if (L - depth < keepLog2) {
            depth = L - keepLog2;
            const uint64_t pm = stackPosMirror[depth];
            nodePos = pm & ((uint64_t(1) << 61) - 1ul);
            nodeMirror = uint(pm >> 61);
            nodeBase = stackBase[depth];
        }
        v = next;
    }
    return result;
}

// DagTracer::find: the entry entry of the active voxel at an index coordinate.
bool findVoxel(i64vec3 voxel, out uint64_t entry) {
    entry = 0ul;
    if (gLog2Size == 0u) return false;
    const int64_t size = int64_t(1) << gLog2Size;
    i64vec3 v;
    for (int a = 0; a < 3; ++a) {
        v[a] = voxel[a] - gRootOrigin[a];
        if (v[a] < 0l || v[a] >= size) return false;
    }
    uint64_t pos = 0ul, base = 0ul;
    uint mirror = gRootReflection;
    const uint64_t x = uint64_t(v[0]), y = uint64_t(v[1]), z = uint64_t(v[2]);
    for (uint depth = 0u; depth < kMaxInnerLevels; ++depth) {
        const uint header = innerWord(pos);
        if (header == 0u) { entry = base; return true; }
        uint64_t offset;
        if (!dagDescend(0u, pos, header, x, y, z, gLog2Size - depth - 1u, offsetWordsAt(depth), mirror, base, offset)) return false;
        if (depth + 1u == gInnerLevels) return dagLeafEntry(leafMask(offset), x, y, z, mirror, base, entry);
        pos = P.levelStart[depth + 1u] + offset;
    }
    return false;
}

#endif
