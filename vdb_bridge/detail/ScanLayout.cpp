// See ScanLayout.h.
#include "vdb_bridge/detail/ScanLayout.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <limits>

#include <fmt/core.h>
#include <openvdb/openvdb.h>

#include "src/util/Error.h"
#include "vdb_bridge/detail/HeaderFieldMeta.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"

namespace vdbdag::bridge::detail {


std::optional<OutFormat> outFormatOf(const std::string& path) {
    std::string name = std::filesystem::path(path).filename().string();
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    const std::string ext = std::filesystem::path(name).extension().string();
    if (name.size() > 7 && name.ends_with(".nii.gz")) return OutFormat::NiiGz;
    if (ext == ".nrrd") return OutFormat::Nrrd;
    if (ext == ".nhdr") return OutFormat::Nhdr;
    if (ext == ".mha") return OutFormat::Mha;
    if (ext == ".mhd") return OutFormat::Mhd;
    if (ext == ".nii") return OutFormat::Nii;
    if (ext == ".raw") return OutFormat::Raw;
    return std::nullopt;
}

namespace {

using Layout = ScanLayout;

std::optional<SampleType> sampleTypeNamed(const std::string& name) {
    for (SampleType t : {SampleType::U8, SampleType::I8, SampleType::U16, SampleType::I16, SampleType::U32, SampleType::I32, SampleType::F32,
                         SampleType::F64})
        if (name == sampleTypeName(t)) return t;
    return std::nullopt;
}

// The active and stored-inactive voxels' bounding box [lo, hi].
bool boundsOf(const GridRecord& g, std::array<int64_t, 3>& lo, std::array<int64_t, 3>& hi) {
    bool any = false;
    auto add = [&](int64_t x, int64_t y, int64_t z, int64_t size) {
        const int64_t p[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) {
            lo[size_t(a)] = any ? std::min(lo[size_t(a)], p[a]) : p[a];
            hi[size_t(a)] = any ? std::max(hi[size_t(a)], p[a] + size - 1) : p[a] + size - 1;
        }
        any = true;
    };
    for (const GridTopology* t : {&g.topology, &g.inactiveTopology}) {
        for (const Brick& b : t->bricks)
            for (uint64_t m = b.mask; m; m &= m - 1) {
                const int bit = std::countr_zero(m);
                add(b.x + (bit & 3), b.y + ((bit >> 2) & 3), b.z + (bit >> 4), 1);
            }
        for (const Tile& tile : t->tiles) add(tile.x, tile.y, tile.z, int64_t(1) << tile.log2Size);
    }
    return any;
}

// The narrowest integer sample type that holds [lo, hi], or none.
std::optional<SampleType> integerTypeFor(double lo, double hi) {
    for (SampleType t : {SampleType::U8, SampleType::I8, SampleType::U16, SampleType::I16, SampleType::U32, SampleType::I32}) {
        const auto [min, max] = sampleRange(t);
        if (lo >= min && hi <= max) return t;
    }
    return std::nullopt;
}

// Formats with a place for a rescale: value = stored * slope + intercept.
bool hasRescaleField(OutFormat f) { return f == OutFormat::Nii || f == OutFormat::NiiGz; }

// A rescaled scan into a format without a rescale field: the grid's own
// values in a type that holds them exactly (the smallest integer type for
// an integer rescale, float or double otherwise), or, with storedValues,
// the stored integers with the rescale as key/value pairs.
void chooseValuesWithoutRescale(Layout& l, const GridRecord& grid, unsigned bitsStored, OutFormat format, const DenseExportOptions& options,
                                const std::string& path, std::vector<std::string>& notes) {
    const std::string fmtName = std::filesystem::path(path).extension().string();
    const std::string rescale = fmt::format("value = sample * {:.17g} + {:.17g}", l.slope, l.intercept);
    if (options.storedValues) {
        if (format == OutFormat::Raw) {
            notes.push_back(fmt::format("wrote the stored {} samples; a .raw file has no header, so the rescale is not in it ({})", sampleTypeName(l.type), rescale));
        } else {
            const bool nrrd = format == OutFormat::Nrrd || format == OutFormat::Nhdr;
            l.keyValues.emplace_back(nrrd ? "rescale_slope" : "RescaleSlope", fmt::format("{:.17g}", l.slope));
            l.keyValues.emplace_back(nrrd ? "rescale_intercept" : "RescaleIntercept", fmt::format("{:.17g}", l.intercept));
            notes.push_back(fmt::format("wrote the stored {} samples; {} has no rescale field, so {} is written as the {} {} and {} (readers that do not know them show the stored samples)",
                                        sampleTypeName(l.type), fmtName, rescale, nrrd ? "key/value pairs" : "tags", nrrd ? "rescale_slope" : "RescaleSlope",
                                        nrrd ? "rescale_intercept" : "RescaleIntercept"));
        }
        return;
    }
    const SampleType stored = l.type;
    l.rescaled = false;
    switch (grid.valueType) {
        case ValueType::Int32:
        case ValueType::Int64: {
            const auto [a, b] = sampleRange(stored, bitsStored);  // the stored samples' range (DICOM Bits Stored)
            const double r0 = a * l.slope + l.intercept, r1 = b * l.slope + l.intercept;
            const std::optional<SampleType> t = integerTypeFor(std::min(r0, r1), std::max(r0, r1));
            if (!t) throw Error(path + ": grid '" + grid.name + "' holds values beyond 32-bit integers; write it as .nii/.nii.gz (stored samples and the rescale) or .vdb");
            l.type = *t;
            break;
        }
        case ValueType::Double: l.type = SampleType::F64; break;
        default: l.type = SampleType::F32; break;
    }
    notes.push_back(fmt::format("wrote the grid's values as {} samples ({} has no rescale field; the scan stored {} samples with {}); --stored-values writes those instead",
                                sampleTypeName(l.type), fmtName, sampleTypeName(stored), rescale));
}

// The recorded NIfTI header, and whether the grid's transform is still the
// one it gives (to 1e-6 of the voxel size).
void attachNiftiFields(Layout& l, const openvdb::GridBase& g) {
    l.nifti = detail::headerFieldsWithPrefix(g, "nifti_");
    NiftiGridTransform t;
    if (!niftiGridTransformOf(l.nifti, t) || t.lps != (l.space == "LPS")) return;
    double voxel = std::numeric_limits<double>::infinity();
    for (const auto& a : l.axes) voxel = std::min(voxel, std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]));
    const double tolerance = 1e-6 * voxel;
    bool same = true;
    for (int a = 0; a < 3; ++a) {
        for (int c = 0; c < 3; ++c) same = same && std::abs(t.axes[size_t(a)][size_t(c)] - l.axes[size_t(a)][size_t(c)]) <= tolerance;
        same = same && std::abs(t.origin[size_t(a)] - l.origin[size_t(a)]) <= tolerance;
    }
    l.niftiGeometry = same;
}

// The source's unit of world coordinates: NIfTI's xyzt_units (its spatial
// bits: 1 m, 2 mm, 3 micron) or NRRD's space units (the first axis's; the
// writer gives all three the same), else none.
std::string spaceUnitOf(const openvdb::GridBase& g) {
    if (auto u = g.getMetadata<openvdb::Int64Metadata>("nifti_xyzt_units")) {
        switch (u->value() & 7) {
            case 1: return "m";
            case 2: return "mm";
            case 3: return "um";
            default: return "";
        }
    }
    if (auto u = g.getMetadata<openvdb::StringMetadata>("nrrd_field_space units")) {
        const std::string& text = u->value();
        const size_t open = text.find('"'), close = open == std::string::npos ? open : text.find('"', open + 1);
        if (close != std::string::npos) {
            const std::string unit = text.substr(open + 1, close - open - 1);
            if (unit == "mm" || unit == "m" || unit == "um" || unit == "µm" || unit == "micron") return unit == "mm" || unit == "m" ? unit : "um";
        }
    }
    return "";
}

} // namespace

ScanLayout layoutOf(const GridRecord& grid, const std::string& path, OutFormat format, const DenseExportOptions& options, std::vector<std::string>& notes) {
    const std::string what = path + ": grid '" + grid.name + "'";
    const openvdb::GridBase::Ptr g = detail::readDescriptor(grid.vdbDescriptor, what);
    Layout l;
    if (auto t = g->getMetadata<openvdb::StringMetadata>("source_sample_type")) {
        const auto type = sampleTypeNamed(t->value());
        if (!type) throw Error(what + ": its source_sample_type '" + t->value() + "' is not a sample type");
        l.type = *type;
    } else {
        switch (grid.valueType) {
            case ValueType::Int32:
            case ValueType::Vec3I: l.type = SampleType::I32; break;
            case ValueType::Float:
            case ValueType::Vec3S: l.type = SampleType::F32; break;
            case ValueType::Double:
            case ValueType::Vec3D: l.type = SampleType::F64; break;
            case ValueType::Bool:
            case ValueType::Mask: l.type = SampleType::U8; break;
            default:
                throw Error(what + " holds " + valueTypeName(grid.valueType) + " values, which a scan file cannot hold (int32, float, double, bool, mask and vec3 can)");
        }
    }
    if (grid.valueType == ValueType::Vec3I || grid.valueType == ValueType::Vec3S || grid.valueType == ValueType::Vec3D) {
        l.components = 3;
        if (auto c = g->getMetadata<openvdb::StringMetadata>("source_colour"); c && c->value() == "rgb") l.colour = true;
    }
    if (auto s = g->getMetadata<openvdb::DoubleMetadata>("source_rescale_slope")) {
        l.rescaled = true;
        l.slope = s->value();
        if (auto i = g->getMetadata<openvdb::DoubleMetadata>("source_rescale_intercept")) l.intercept = i->value();
        if (!std::isfinite(l.slope) || l.slope == 0 || !std::isfinite(l.intercept)) throw Error(what + ": its rescale slope/intercept is not usable");
    }
    if (auto s = g->getMetadata<openvdb::StringMetadata>("space"); s && s->value() == "LPS") l.space = "LPS";
    l.spaceUnit = spaceUnitOf(*g);
    std::array<int64_t, 3> lo{0, 0, 0}, hi{-1, -1, -1};
    const bool any = boundsOf(grid, lo, hi);
    if (auto d = g->getMetadata<openvdb::Vec3IMetadata>("source_dims")) {
        for (int a = 0; a < 3; ++a) l.dims[size_t(a)] = d->value()[a];
        for (int a = 0; a < 3; ++a)
            if (l.dims[size_t(a)] < 1) throw Error(what + ": its source_dims are not positive");
        if (any && (lo[0] < 0 || lo[1] < 0 || lo[2] < 0 || hi[0] >= l.dims[0] || hi[1] >= l.dims[1] || hi[2] >= l.dims[2]))
            throw Error(what + ": voxels lie outside its recorded extent " + fmt::format("{}x{}x{}", l.dims[0], l.dims[1], l.dims[2]));
    } else {
        if (!any) throw Error(what + " has no voxels, so no extent to write (and no source_dims)");
        l.lo = lo;
        for (int a = 0; a < 3; ++a) l.dims[size_t(a)] = hi[size_t(a)] - lo[size_t(a)] + 1;
    }
    for (int a = 0; a < 3; ++a)
        if (l.dims[size_t(a)] > std::numeric_limits<int32_t>::max()) throw Error(what + ": its extent is too large for a scan file");
    const auto& m = grid.indexToWorld;  // world = [i j k 1] * M
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) l.axes[size_t(a)][size_t(c)] = m[size_t(4 * a + c)];
    for (int c = 0; c < 3; ++c)
        l.origin[size_t(c)] = m[size_t(12 + c)] + double(l.lo[0]) * m[size_t(c)] + double(l.lo[1]) * m[size_t(4 + c)] + double(l.lo[2]) * m[size_t(8 + c)];
    if (l.rescaled && !hasRescaleField(format)) {
        unsigned bitsStored = 0;
        if (auto b = g->getMetadata<openvdb::Int64Metadata>("source_bits_stored"); b && b->value() > 0 && b->value() < 32) bitsStored = unsigned(b->value());
        chooseValuesWithoutRescale(l, grid, bitsStored, format, options, path, notes);
    }
    if (format == OutFormat::Nii || format == OutFormat::NiiGz) attachNiftiFields(l, *g);
    // The source's own NRRD fields and key/value pairs, MetaImage tags.
    const bool nrrd = format == OutFormat::Nrrd || format == OutFormat::Nhdr, mha = format == OutFormat::Mha || format == OutFormat::Mhd;
    auto strings = [&](const std::string& prefix, std::vector<std::pair<std::string, std::string>>& out) {
        for (const auto& [key, value] : detail::headerFieldsWithPrefix(*g, prefix))
            if (const auto* text = std::get_if<std::string>(&value)) out.emplace_back(key.substr(prefix.size()), *text);
    };
    if (nrrd) {
        strings("nrrd_field_", l.nrrdFields);
        strings("nrrd_key_", l.keyValues);
    }
    if (mha) strings("mha_tag_", l.keyValues);
    // What another format's header held and this one has no place for: one
    // note line (the fields stay in the grid's metadata, docs/SCAN_METADATA.md).
    struct Foreign {
        const char* prefix;
        const char* what;
        bool carried;
    };
    const Foreign foreign[] = {{"nifti_", "NIfTI header fields", format == OutFormat::Nii || format == OutFormat::NiiGz},
                               {"nrrd_", "NRRD fields and key/value pairs", nrrd},
                               {"mha_tag_", "MetaImage tags", mha},
                               {"dicom_", "DICOM tags", false}};
    std::string lost;
    for (const Foreign& f : foreign) {
        const size_t n = f.carried ? 0 : detail::headerFieldsWithPrefix(*g, f.prefix).size();
        if (n) lost += fmt::format("{}{} {} ({}*)", lost.empty() ? "" : ", ", n, f.what, f.prefix);
    }
    if (!lost.empty())
        notes.push_back("the source's " + lost + " have no place in " + std::filesystem::path(path).filename().string() +
                        " and are not written; they stay in the grid's metadata (.ssvdag, .vdb)");
    return l;
}


} // namespace vdbdag::bridge::detail
