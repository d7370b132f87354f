// See NiftiHeader.h. libnifti reads and checks the header (either version,
// either byte order, single file or pair, gzip or not); the samples are left
// to DenseSampleStream, which streams them slab by slab from the offset
// libnifti reports (inside the gzip stream for a .nii.gz).
#include "vdb_bridge/NiftiHeader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>

#include <nifti2_io.h>
#include <zlib.h>

#include "src/util/Error.h"
#include "vdb_bridge/NiftiFields.h"

namespace vdbdag::bridge {
namespace {

struct NiftiDeleter {
    void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};

const char* niftiTypeName(int datatype) {
    const char* name = nifti_datatype_string(datatype);
    return name ? name : "unknown";
}

SampleType sampleTypeOf(const nifti_image& nim, const std::string& path) {
    switch (nim.datatype) {
        case DT_UINT8: return SampleType::U8;
        case DT_INT8: return SampleType::I8;
        case DT_UINT16: return SampleType::U16;
        case DT_INT16: return SampleType::I16;
        case DT_UINT32: return SampleType::U32;
        case DT_INT32: return SampleType::I32;
        case DT_FLOAT32: return SampleType::F32;
        case DT_FLOAT64: return SampleType::F64;
        case DT_COMPLEX64:
        case DT_COMPLEX128:
        case DT_COMPLEX256:
            throw Error(path + ": NIfTI datatype " + niftiTypeName(nim.datatype) + " (complex samples) is not supported: convert the magnitude or the real and imaginary parts to separate files");
        case DT_RGB24: return SampleType::U8;  // 3 components, a colour grid
        case DT_RGBA32: return SampleType::U8;  // 4 components: a colour grid and an alpha grid
        default:
            throw Error(path + ": NIfTI datatype " + niftiTypeName(nim.datatype) + " (code " + std::to_string(nim.datatype) + ") is not supported");
    }
}

// What libnifti would complain about on stderr (whatever its debug level)
// rather than in its return value, checked first: the header size and the
// datatype code. A .nii.gz is read through zlib, as libnifti reads it.
void precheck(const std::string& path) {
    gzFile f = gzopen(path.c_str(), "rb");
    if (!f) return;  // libnifti reports it
    uint8_t h[540] = {};
    const int got = gzread(f, h, sizeof h);
    gzclose(f);
    if (got < 348) throw Error(path + ": too short for a NIfTI header (" + std::to_string(got < 0 ? 0 : got) + " bytes, at least 348)");
    auto i32 = [&](size_t at, bool swap) {
        uint32_t v = uint32_t(h[at]) | uint32_t(h[at + 1]) << 8 | uint32_t(h[at + 2]) << 16 | uint32_t(h[at + 3]) << 24;
        return swap ? __builtin_bswap32(v) : v;
    };
    auto i16 = [&](size_t at, bool swap) {
        const uint16_t v = uint16_t(h[at] | h[at + 1] << 8);
        return int16_t(swap ? __builtin_bswap16(v) : v);
    };
    size_t datatypeAt = 0;
    bool swap = false;
    for (bool s : {false, true}) {
        if (i32(0, s) == 348) { datatypeAt = 70; swap = s; }
        if (i32(0, s) == 540 && got >= 540) { datatypeAt = 12; swap = s; }
    }
    if (!datatypeAt) throw Error(path + ": not a NIfTI header (sizeof_hdr is " + std::to_string(i32(0, false)) + ", neither 348 nor 540)");
    // dim[0] in 1..7 and dim[1..dim[0]] positive (NIfTI-1: int16 at byte
    // 40; NIfTI-2: int64 at byte 16).
    int64_t dim[8];
    for (int d = 0; d < 8; ++d) {
        if (datatypeAt == 70) {
            dim[d] = i16(40 + 2 * size_t(d), swap);
        } else {
            const uint64_t lo = i32(16 + 8 * size_t(d), swap), hi = i32(20 + 8 * size_t(d), swap);
            dim[d] = int64_t(swap ? (lo << 32 | hi) : (hi << 32 | lo));
        }
    }
    if (dim[0] < 1 || dim[0] > 7) throw Error(path + ": NIfTI dim[0] = " + std::to_string(dim[0]) + " is outside 1..7");
    for (int d = 1; d <= dim[0]; ++d)
        if (dim[d] < 1) throw Error(path + ": NIfTI dim[" + std::to_string(d) + "] = " + std::to_string(dim[d]) + " is not positive");
    const int datatype = i16(datatypeAt, swap);
    static const int known[] = {DT_UINT8, DT_INT16, DT_INT32, DT_FLOAT32, DT_COMPLEX64, DT_FLOAT64, DT_RGB24, DT_INT8, DT_UINT16,
                                DT_UINT32, DT_INT64, DT_UINT64, DT_FLOAT128, DT_COMPLEX128, DT_COMPLEX256, DT_RGBA32};
    if (std::find(std::begin(known), std::end(known), datatype) == std::end(known))
        throw Error(path + ": NIfTI datatype code " + std::to_string(datatype) + " is not a NIfTI datatype");
}

// Vectors on the 4th axis: a 4th dimension of 3 under a vector intent
// (RGB_VECTOR, VECTOR, DISPVECT), as some writers store them instead of in
// the 5th; one vector volume, not three.
bool vectorsOnFourthAxis(const nifti_image& n) {
    const bool vectorIntent = n.intent_code == NIFTI_INTENT_RGB_VECTOR || n.intent_code == NIFTI_INTENT_VECTOR || n.intent_code == NIFTI_INTENT_DISPVECT;
    return vectorIntent && n.ndim == 4 && n.nt == 3 && n.datatype != DT_RGB24 && n.datatype != DT_RGBA32;
}

} // namespace

DenseVolume readNiftiHeader(const std::string& path, std::optional<int64_t> volume) {
    static std::once_flag quiet;
    std::call_once(quiet, [] { nifti_set_debug_level(0); });  // errors come back as one vdbdag::Error, never on stderr
    precheck(path);
    std::unique_ptr<nifti_image, NiftiDeleter> nim(nifti_image_read(path.c_str(), 0));
    if (!nim) throw Error(path + ": not a readable NIfTI-1 or NIfTI-2 header (missing, truncated, or a field out of range)");
    const nifti_image& n = *nim;
    DenseVolume v;
    v.format = DenseFormat::Nifti;
    v.headerPath = path;
    v.type = sampleTypeOf(n, path);
    if (n.datatype == DT_RGB24 || n.datatype == DT_RGBA32) {
        v.components = 3;
        v.colour = true;
        if (n.datatype == DT_RGBA32) v.storedComponents = 4;  // importDense reads the alpha channel as a second grid
    }
    if (n.nbyper != int(sampleBytes(v.type) * v.componentsInFile()))
        throw Error(path + ": NIfTI bitpix gives " + std::to_string(n.nbyper) + " bytes per sample, datatype " + niftiTypeName(n.datatype) + " needs " +
                    std::to_string(sampleBytes(v.type) * v.componentsInFile()));
    if (n.ndim < 1 || n.ndim > 7) throw Error(path + ": NIfTI dim[0] = " + std::to_string(n.ndim) + " is outside 1..7");
    for (int d = 1; d <= 7; ++d)
        if (n.dim[d] < 1 && d <= n.ndim) throw Error(path + ": NIfTI dim[" + std::to_string(d) + "] = " + std::to_string(n.dim[d]) + " is not positive");
    // A 5th dimension of 3 is a vector per voxel (NIFTI_INTENT_VECTOR and
    // the like): its components are planes nx*ny*nz*nt samples apart.
    const bool vectorOnT = vectorsOnFourthAxis(n);  // the same, as some writers store it
    const bool vector = (n.ndim >= 5 && n.nu == 3 && n.nv <= 1 && n.nw <= 1 && v.components == 1) || vectorOnT;
    if (!vector && (n.nu > 1 || n.nv > 1 || n.nw > 1))
        throw Error(path + ": NIfTI dimensions 5 to 7 (" + std::to_string(n.nu) + "x" + std::to_string(n.nv) + "x" + std::to_string(n.nw) +
                    ", intent " + std::to_string(n.intent_code) + ") are not supported (a 5th dimension of 3, a vector per voxel, is)");
    v.dims = {n.nx, n.ny, n.nz};
    const int64_t volumes = vectorOnT ? 1 : (n.nt > 0 ? n.nt : 1);
    int64_t chosen = 0;
    if (volume) {
        if (*volume < 0 || *volume >= volumes)
            throw Error(path + ": --volume " + std::to_string(*volume) + " is out of range: the file holds " + std::to_string(volumes) + " volume" +
                        (volumes == 1 ? "" : "s") + " (0.." + std::to_string(volumes - 1) + ")");
        chosen = *volume;
        if (volumes > 1) {
            v.gridName = scanNameOf(path) + "_t" + std::to_string(chosen);
            v.volumeIndex = chosen;
            v.volumeCount = volumes;
        }
    } else if (volumes > 1) {
        throw Error(path + ": a 4-D NIfTI file with " + std::to_string(volumes) + " volumes of " + std::to_string(n.nx) + "x" + std::to_string(n.ny) +
                    "x" + std::to_string(n.nz) + ": pick one with --volume 0.." + std::to_string(volumes - 1));
    }

    // Samples: in the image file after iname_offset; a gzipped file is one
    // stream from its first byte (the header of a .nii.gz included).
    if (!n.iname) throw Error(path + ": NIfTI header names no image file");
    v.dataPath = n.iname;
    if (v.dataPath != path) v.dataNameInHeader = std::string(v.dataPath).substr(v.dataPath.find_last_of('/') + 1);
    v.bigEndian = n.byteorder == 2;  // MSB_FIRST (nifti1_io.h; nifti2_io.h does not define it)
    const uint64_t volumeBytes = uint64_t(n.nx) * uint64_t(n.ny) * uint64_t(n.nz) * uint64_t(n.nbyper);
    if (vector) {
        v.components = 3;
        v.componentStride = volumeBytes * uint64_t(volumes);
    }
    const int64_t skip = n.iname_offset + int64_t(uint64_t(chosen) * volumeBytes);
    if (nifti_is_gzfile(n.iname)) {
        v.encoding = DataEncoding::Zlib;
        v.dataOffset = 0;
        v.decodedSkip = skip;
    } else {
        v.encoding = DataEncoding::Raw;
        v.dataOffset = skip;
    }

    // The transform, by the NIfTI rules: sform (method 3), else qform
    // (method 2), else pixdim scaling (method 1, no orientation), in RAS
    // (describeDense turns it into vdbdag's LPS).
    const nifti_dmat44* m = n.sform_code > 0 ? &n.sto_xyz : (n.qform_code > 0 ? &n.qto_xyz : nullptr);
    if (m) {
        for (int a = 0; a < 3; ++a)
            for (int c = 0; c < 3; ++c) v.axes[size_t(a)][size_t(c)] = m->m[c][a];
        for (int c = 0; c < 3; ++c) v.origin[size_t(c)] = m->m[c][3];
        v.space = "RAS";
    } else {
        const double d[3] = {n.dx, n.dy, n.dz};
        for (int a = 0; a < 3; ++a) {
            v.axes[size_t(a)] = {0, 0, 0};
            v.axes[size_t(a)][size_t(a)] = d[a] > 0 && std::isfinite(d[a]) ? d[a] : 1.0;
        }
    }

    // Scaling: ignored when scl_slope is 0 or not finite (NIfTI and nibabel).
    if (std::isfinite(n.scl_slope) && n.scl_slope != 0) {
        v.rescaleSlope = n.scl_slope;
        v.rescaleIntercept = std::isfinite(n.scl_inter) ? n.scl_inter : 0.0;
    }
    v.headerFields = niftiFieldsOf(path);  // every field, for a decode back to NIfTI (NiftiFields.h)
    v.validate();
    return v;
}

int64_t niftiVolumeCount(const std::string& path) {
    precheck(path);
    std::unique_ptr<nifti_image, NiftiDeleter> nim(nifti_image_read(path.c_str(), 0));
    if (!nim) throw Error(path + ": not a readable NIfTI-1 or NIfTI-2 header (missing, truncated, or a field out of range)");
    const bool vectorOnT = vectorsOnFourthAxis(*nim);
    return nim->nt > 1 && !vectorOnT ? nim->nt : 1;  // vectors on the 4th axis are one vector volume (readNiftiHeader)
}

} // namespace vdbdag::bridge
