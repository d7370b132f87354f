// See ScanHeaderWriters.h.
#include "vdb_bridge/detail/ScanHeaderWriters.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

#include <fmt/core.h>
#include <nifti2_io.h>

#include "src/util/Error.h"
#include "vdb_bridge/detail/HeaderText.h"

namespace vdbdag::bridge::detail {
namespace {

using Layout = ScanLayout;


std::string g17(double x) { return fmt::format("{:.17g}", x); }

const char* nrrdTypeName(SampleType t) {
    switch (t) {
        case SampleType::U8: return "uint8";
        case SampleType::I8: return "int8";
        case SampleType::U16: return "uint16";
        case SampleType::I16: return "int16";
        case SampleType::U32: return "uint32";
        case SampleType::I32: return "int32";
        case SampleType::F32: return "float";
        case SampleType::F64: return "double";
    }
    return "";
}

const char* metTypeName(SampleType t) {
    switch (t) {
        case SampleType::U8: return "MET_UCHAR";
        case SampleType::I8: return "MET_CHAR";
        case SampleType::U16: return "MET_USHORT";
        case SampleType::I16: return "MET_SHORT";
        case SampleType::U32: return "MET_UINT";
        case SampleType::I32: return "MET_INT";
        case SampleType::F32: return "MET_FLOAT";
        case SampleType::F64: return "MET_DOUBLE";
    }
    return "";
}

int niftiDatatype(SampleType t) {
    switch (t) {
        case SampleType::U8: return DT_UINT8;
        case SampleType::I8: return DT_INT8;
        case SampleType::U16: return DT_UINT16;
        case SampleType::I16: return DT_INT16;
        case SampleType::U32: return DT_UINT32;
        case SampleType::I32: return DT_INT32;
        case SampleType::F32: return DT_FLOAT32;
        case SampleType::F64: return DT_FLOAT64;
    }
    return 0;
}

} // namespace

std::string nrrdHeader(const Layout& l, const std::string& dataFile) {
    std::string h = "NRRD0004\n# written by vdbdag decode\n";
    const bool vector = l.components == 3, series = l.volumes > 1;
    if (vector && series) throw Error("internal error: a NRRD of vectors in volumes");
    const int dimension = vector || series ? 4 : 3;
    h += fmt::format("type: {}\ndimension: {}\n", nrrdTypeName(l.type), dimension);
    h += l.space == "LPS" ? "space: left-posterior-superior\n" : "space dimension: 3\n";
    h += fmt::format("sizes: {}{} {} {}{}\n", vector ? "3 " : "", l.dims[0], l.dims[1], l.dims[2], series ? " " + std::to_string(l.volumes) : "");
    h += vector ? "space directions: none" : "space directions:";
    for (const auto& a : l.axes) h += fmt::format(" ({},{},{})", g17(a[0]), g17(a[1]), g17(a[2]));
    h += fmt::format("{}\nkinds: {}domain domain domain{}\nendian: little\nencoding: raw\n", series ? " none" : "",
                     vector ? (l.colour ? "RGB-color " : "vector ") : "", series ? " list" : "");
    h += fmt::format("space origin: ({},{},{})\n", g17(l.origin[0]), g17(l.origin[1]), g17(l.origin[2]));
    const bool unitsGiven = std::any_of(l.nrrdFields.begin(), l.nrrdFields.end(), [](const auto& f) { return f.first == "space units"; });
    if (!unitsGiven && !l.spaceUnit.empty())  // the unit a NIfTI source's xyzt_units named
        h += fmt::format("space units: \"{0}\" \"{0}\" \"{0}\"\n", l.spaceUnit);
    // The source's fields; a per-axis one only when it has a value per axis
    // of this file (one volume of a 4-D series is a 3-D file).
    static const char* perAxis[] = {"thicknesses", "labels", "units", "centers", "axis mins", "axis maxs"};
    for (const auto& [name, value] : l.nrrdFields) {
        if (std::find(std::begin(perAxis), std::end(perAxis), name) != std::end(perAxis)) {
            const size_t quotes = size_t(std::count(value.begin(), value.end(), '"'));  // "a b" "c": quoted values may hold spaces
            if ((quotes ? quotes / 2 : detail::tokens(value).size()) != size_t(dimension)) continue;
        }
        h += name + ": " + value + "\n";
    }
    for (const auto& [key, value] : l.keyValues) h += key + ":=" + value + "\n";
    if (!dataFile.empty()) h += "data file: " + dataFile + "\n";
    else h += "\n";
    return h;
}

// TransformMatrix triple a = index axis a's direction; ElementSpacing its length.
std::string metaImageHeader(const Layout& l, const std::string& dataFile) {
    std::string h = "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\nTransformMatrix =";
    std::array<double, 3> spacing{};
    for (int a = 0; a < 3; ++a) {
        const auto& v = l.axes[size_t(a)];
        spacing[size_t(a)] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int c = 0; c < 3; ++c) h += " " + g17(v[size_t(c)] / spacing[size_t(a)]);
    }
    h += fmt::format("\nOffset = {} {} {}\nCenterOfRotation = 0 0 0\n", g17(l.origin[0]), g17(l.origin[1]), g17(l.origin[2]));
    if (l.space == "LPS") h += "AnatomicalOrientation = RAI\n";
    if (l.components != 1) h += fmt::format("ElementNumberOfChannels = {}\n", l.components);
    for (const auto& [key, value] : l.keyValues) h += key + " = " + value + "\n";
    h += fmt::format("ElementSpacing = {} {} {}\nDimSize = {} {} {}\nElementType = {}\nElementDataFile = {}\n", g17(spacing[0]), g17(spacing[1]),
                     g17(spacing[2]), l.dims[0], l.dims[1], l.dims[2], metTypeName(l.type), dataFile.empty() ? "LOCAL" : dataFile);
    return h;
}

namespace {

// A NIfTI single-file header of version H (nifti_1_header: 348 bytes,
// nifti_2_header: 540), its extensions and vox_offset. NIfTI is RAS: the
// grid's (LPS) x and y change sign. The sform carries the exact affine (as
// float in NIfTI-1); the qform too when the axes are orthogonal (a
// quaternion cannot hold a shear). Then the source's own fields go back
// over it (NiftiFields.h).
template <class H>
std::vector<uint8_t> niftiHeaderAs(const Layout& l, const std::string& path, std::vector<std::string>* notes) {
    constexpr bool v1 = std::is_same_v<H, nifti_1_header>;
    using Dim = std::remove_extent_t<decltype(H::dim)>;
    using Real = std::remove_extent_t<decltype(H::pixdim)>;
    H h;
    std::memset(&h, 0, sizeof h);
    h.sizeof_hdr = v1 ? 348 : 540;
    h.dim[0] = 3;
    for (int a = 0; a < 3; ++a) h.dim[a + 1] = Dim(l.dims[size_t(a)]);
    for (int a = 4; a < 8; ++a) h.dim[a] = 1;
    h.datatype = decltype(h.datatype)(niftiDatatype(l.type));
    h.bitpix = decltype(h.bitpix)(8 * sampleBytes(l.type));
    if (l.colour) {
        if (l.type != SampleType::U8) throw Error(path + ": NIfTI holds RGB colours as 8-bit samples; this grid's are " + sampleTypeName(l.type));
        h.datatype = DT_RGB24;
        h.bitpix = 24;
    } else if (l.components == 3) {  // a vector per voxel: the 5th dimension, in planes
        h.dim[0] = 5;
        h.dim[5] = 3;
        h.intent_code = NIFTI_INTENT_VECTOR;
    }
    if (l.volumes > 1) {  // a time series: the 4th dimension
        h.dim[0] = std::max<Dim>(h.dim[0], 4);
        h.dim[4] = Dim(l.volumes);
    }
    h.scl_slope = l.rescaled ? Real(l.slope) : Real(0);
    h.scl_inter = l.rescaled ? Real(l.intercept) : Real(0);
    // The unit the source named (an NRRD's space units), else mm for a patient space.
    h.xyzt_units = l.spaceUnit == "m" ? NIFTI_UNITS_METER : l.spaceUnit == "um" ? NIFTI_UNITS_MICRON
                 : l.spaceUnit == "mm" || !l.space.empty() ? NIFTI_UNITS_MM : 0;
    std::snprintf(h.descrip, sizeof h.descrip, "vdbdag decode");
    // A grid without a named space is taken as LPS too, as ITK does when it
    // writes NIfTI from its (LPS) physical space: read back, it is the same.
    const double flip[3] = {-1.0, -1.0, 1.0};
    nifti_dmat44 m;
    std::memset(&m, 0, sizeof m);
    for (int r = 0; r < 3; ++r) {
        for (int a = 0; a < 3; ++a) m.m[r][a] = flip[r] * l.axes[size_t(a)][size_t(r)];
        m.m[r][3] = flip[r] * l.origin[size_t(r)];
    }
    m.m[3][3] = 1;
    Real* srow[3] = {h.srow_x, h.srow_y, h.srow_z};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) srow[r][c] = Real(m.m[r][c]);
    h.sform_code = l.space.empty() ? NIFTI_XFORM_ALIGNED_ANAT : NIFTI_XFORM_SCANNER_ANAT;
    double length[3];
    for (int a = 0; a < 3; ++a) length[a] = std::sqrt(m.m[0][a] * m.m[0][a] + m.m[1][a] * m.m[1][a] + m.m[2][a] * m.m[2][a]);
    bool orthogonal = true;
    for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b) {
            const double dot = m.m[0][a] * m.m[0][b] + m.m[1][a] * m.m[1][b] + m.m[2][a] * m.m[2][b];
            if (std::abs(dot) > 1e-6 * length[a] * length[b]) orthogonal = false;
        }
    double qb, qc, qd, qx, qy, qz, dx, dy, dz, qfac;
    nifti_dmat44_to_quatern(m, &qb, &qc, &qd, &qx, &qy, &qz, &dx, &dy, &dz, &qfac);
    h.pixdim[0] = Real(qfac);
    for (int a = 0; a < 3; ++a) h.pixdim[a + 1] = Real(length[a]);
    if (orthogonal) {
        h.qform_code = h.sform_code;
        h.quatern_b = Real(qb);
        h.quatern_c = Real(qc);
        h.quatern_d = Real(qd);
        h.qoffset_x = Real(qx);
        h.qoffset_y = Real(qy);
        h.qoffset_z = Real(qz);
    }
    if (v1) std::memcpy(h.magic, "n+1", 4);
    else std::memcpy(h.magic, "n+2\0\r\n\032\n", 8);
    if (!l.nifti.empty()) {
        NiftiRestore how;
        how.geometry = l.niftiGeometry;
        if (l.rescaled) { how.slope = l.slope; how.intercept = l.intercept; }
        std::vector<std::string> lost = restoreNiftiFields(l.nifti, how, h);
        if (notes) notes->insert(notes->end(), lost.begin(), lost.end());
    }
    // Extensions (each esize bytes: size, code, payload, a multiple of 16),
    // then the samples at vox_offset.
    const auto extensions = niftiExtensionsOf(l.nifti);
    size_t offset = sizeof h + 4;
    for (const auto& e : extensions) offset += (8 + e.second.size() + 15) / 16 * 16;
    h.vox_offset = decltype(h.vox_offset)(offset);
    std::vector<uint8_t> bytes(offset, 0);
    std::memcpy(bytes.data(), &h, sizeof h);
    bytes[sizeof h] = extensions.empty() ? 0 : 1;  // the extender's first byte
    size_t at = sizeof h + 4;
    for (const auto& [code, data] : extensions) {
        const int32_t esize = int32_t((8 + data.size() + 15) / 16 * 16), ecode = code;
        std::memcpy(bytes.data() + at, &esize, 4);
        std::memcpy(bytes.data() + at + 4, &ecode, 4);
        std::memcpy(bytes.data() + at + 8, data.data(), data.size());
        at += size_t(esize);
    }
    return bytes;
}

} // namespace

// NIfTI-2 when the source was, or when an axis exceeds NIfTI-1's 32767.
std::vector<uint8_t> niftiHeader(const Layout& l, const std::string& path, std::vector<std::string>* notes) {
    bool v2 = false;
    if (auto it = l.nifti.find("nifti_version"); it != l.nifti.end()) v2 = std::get_if<int64_t>(&it->second) && std::get<int64_t>(it->second) == 2;
    for (int a = 0; a < 3; ++a)
        if (l.dims[size_t(a)] > 32767) v2 = true;
    return v2 ? niftiHeaderAs<nifti_2_header>(l, path, notes) : niftiHeaderAs<nifti_1_header>(l, path, notes);
}

} // namespace vdbdag::bridge::detail
