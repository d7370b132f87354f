// See NiftiFields.h. One visitor names every kept field of either header
// version; reading, restoring and the documentation's key list follow it.
#include "vdb_bridge/NiftiFields.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <type_traits>

#include <fmt/core.h>
#include <nifti2_io.h>

#include "src/util/Base64.h"
#include "src/util/Error.h"

namespace vdbdag::bridge {
namespace {

constexpr const char* kPrefix = "nifti_";

// Every kept field of H (nifti_1_header or nifti_2_header), by its name in
// the standard. The ANALYZE 7.5 leftovers exist in NIfTI-1 only.
template <class H, class F>
void visitFields(H& h, F&& f) {
    f("dim_info", h.dim_info);
    f("dim", h.dim);
    f("intent_p1", h.intent_p1);
    f("intent_p2", h.intent_p2);
    f("intent_p3", h.intent_p3);
    f("intent_code", h.intent_code);
    f("slice_start", h.slice_start);
    f("pixdim", h.pixdim);
    f("scl_slope", h.scl_slope);
    f("scl_inter", h.scl_inter);
    f("slice_end", h.slice_end);
    f("slice_code", h.slice_code);
    f("xyzt_units", h.xyzt_units);
    f("cal_max", h.cal_max);
    f("cal_min", h.cal_min);
    f("slice_duration", h.slice_duration);
    f("toffset", h.toffset);
    f("descrip", h.descrip);
    f("aux_file", h.aux_file);
    f("qform_code", h.qform_code);
    f("sform_code", h.sform_code);
    f("quatern_b", h.quatern_b);
    f("quatern_c", h.quatern_c);
    f("quatern_d", h.quatern_d);
    f("qoffset_x", h.qoffset_x);
    f("qoffset_y", h.qoffset_y);
    f("qoffset_z", h.qoffset_z);
    f("srow_x", h.srow_x);
    f("srow_y", h.srow_y);
    f("srow_z", h.srow_z);
    f("intent_name", h.intent_name);
    if constexpr (std::is_same_v<std::remove_const_t<H>, nifti_1_header>) {
        f("data_type", h.data_type);
        f("db_name", h.db_name);
        f("extents", h.extents);
        f("session_error", h.session_error);
        f("regular", h.regular);
        f("glmax", h.glmax);
        f("glmin", h.glmin);
    }
}

// Which restore rule a field follows (NiftiFields.h).
enum class Group { Plain, Geometry, Dims, Scale };
Group groupOf(const std::string& name) {
    static const char* geometry[] = {"qform_code", "sform_code", "quatern_b", "quatern_c", "quatern_d", "qoffset_x",
                                     "qoffset_y",  "qoffset_z",  "srow_x",    "srow_y",    "srow_z"};
    for (const char* g : geometry)
        if (name == g) return Group::Geometry;
    if (name == "dim" || name == "pixdim") return Group::Dims;  // pixdim[0..3] follow the geometry (restoreInto)
    if (name == "scl_slope" || name == "scl_inter") return Group::Scale;
    return Group::Plain;
}

template <typename T>
constexpr bool isCharArray = std::is_array_v<T> && std::is_same_v<std::remove_extent_t<T>, char>;

template <typename T>
HeaderField::Value valueOf(const T& field) {
    if constexpr (isCharArray<T>) {
        return std::string(field, strnlen(field, std::extent_v<T>));
    } else if constexpr (std::is_array_v<T>) {
        std::string list;
        for (size_t i = 0; i < std::extent_v<T>; ++i) list += fmt::format("{}{:.17g}", i ? " " : "", double(field[i]));
        return list;
    } else if constexpr (std::is_integral_v<T>) {
        return int64_t(field);
    } else {
        return double(field);
    }
}

std::vector<double> numbersOf(const std::string& list) {
    std::vector<double> out;
    const char* p = list.c_str();
    for (;;) {
        char* end = nullptr;
        const double v = std::strtod(p, &end);
        if (end == p) break;
        out.push_back(v);
        p = end;
    }
    return out;
}

// A recorded value into a header field; false when the value does not fit
// the field (a NIfTI-2 value in a NIfTI-1 header, a wrong kind).
template <typename T>
bool assign(T& field, const HeaderField::Value& v, size_t firstIndex = 0, size_t lastIndex = ~size_t(0)) {
    if constexpr (isCharArray<T>) {
        const auto* s = std::get_if<std::string>(&v);
        if (!s || s->size() > std::extent_v<T>) return false;
        std::memset(field, 0, std::extent_v<T>);
        std::memcpy(field, s->data(), s->size());
        return true;
    } else if constexpr (std::is_array_v<T>) {
        const auto* s = std::get_if<std::string>(&v);
        if (!s) return false;
        const std::vector<double> n = numbersOf(*s);
        if (n.size() != std::extent_v<T>) return false;
        using E = std::remove_extent_t<T>;
        for (size_t i = firstIndex; i < n.size() && i <= lastIndex; ++i) {
            if constexpr (std::is_integral_v<E>) {
                if (n[i] != std::trunc(n[i]) || n[i] < double(std::numeric_limits<E>::min()) || n[i] > double(std::numeric_limits<E>::max())) return false;
            }
        }
        for (size_t i = firstIndex; i < n.size() && i <= lastIndex; ++i) field[i] = E(n[i]);
        return true;
    } else if constexpr (std::is_integral_v<T>) {
        const auto* i = std::get_if<int64_t>(&v);
        if (!i || *i < int64_t(std::numeric_limits<T>::min()) || *i > int64_t(std::numeric_limits<T>::max())) return false;
        field = T(*i);
        return true;
    } else {
        const auto* d = std::get_if<double>(&v);
        if (!d) return false;
        field = T(*d);
        return true;
    }
}

const HeaderField::Value* find(const HeaderFieldMap& fields, const std::string& name) {
    auto it = fields.find(kPrefix + name);
    return it == fields.end() ? nullptr : &it->second;
}

template <typename T>
T number(const HeaderFieldMap& fields, const std::string& name, T fallback) {
    const HeaderField::Value* v = find(fields, name);
    if (!v) return fallback;
    if (const auto* i = std::get_if<int64_t>(v)) return T(*i);
    if (const auto* d = std::get_if<double>(v)) return T(*d);
    return fallback;
}

std::vector<double> list(const HeaderFieldMap& fields, const std::string& name) {
    const HeaderField::Value* v = find(fields, name);
    const auto* s = v ? std::get_if<std::string>(v) : nullptr;
    return s ? numbersOf(*s) : std::vector<double>{};
}

// What value = stored * slope + inter gives: NIfTI reads a slope of 0 or
// NaN as no scaling at all.
bool sameScaling(double slopeA, double interA, double slopeB, double interB) {
    const bool identityA = !std::isfinite(slopeA) || slopeA == 0 || (slopeA == 1 && (interA == 0 || !std::isfinite(interA)));
    const bool identityB = !std::isfinite(slopeB) || slopeB == 0 || (slopeB == 1 && (interB == 0 || !std::isfinite(interB)));
    if (identityA || identityB) return identityA && identityB;
    return float(slopeA) == float(slopeB) && float(std::isfinite(interA) ? interA : 0) == float(std::isfinite(interB) ? interB : 0);
}

template <class H>
std::vector<std::string> restoreInto(const HeaderFieldMap& fields, const NiftiRestore& how, H& h) {
    std::vector<std::string> notes, unfit;
    const auto* version = find(fields, "version");
    if (!version) return notes;
    // dim and pixdim[4..7]: when the recorded dims describe as many samples
    // on the same three axes as the header being written.
    bool dimsFit = false;
    if (const std::vector<double> d = list(fields, "dim"); d.size() == 8) {
        double recorded = 1, written = 1;
        for (int i = 1; i <= 7; ++i) {
            recorded *= d[size_t(i)] >= 1 && size_t(i) <= size_t(d[0]) ? d[size_t(i)] : 1;
            written *= h.dim[i] >= 1 && i <= h.dim[0] ? double(h.dim[i]) : 1;
        }
        dimsFit = recorded == written && d[1] == double(h.dim[1]) && d[2] == double(h.dim[2]) && d[3] == double(h.dim[3]);
    }
    visitFields(h, [&](const char* name, auto& field) {
        const HeaderField::Value* v = find(fields, name);
        if (!v) return;
        bool ok = true;
        switch (groupOf(name)) {
            case Group::Plain: ok = assign(field, *v); break;
            case Group::Geometry:
                if (how.geometry) ok = assign(field, *v);
                break;
            case Group::Dims:
                if (std::string(name) == "dim") {
                    if (dimsFit) ok = assign(field, *v);
                } else {  // pixdim: [0..3] with the geometry, [4..7] with the dims
                    if (how.geometry) ok = assign(field, *v, 0, 3);
                    if (ok && dimsFit) ok = assign(field, *v, 4, 7);
                }
                break;
            case Group::Scale: break;  // below, as a pair
        }
        if (!ok) unfit.push_back(name);
    });
    const double slope = number(fields, "scl_slope", 0.0), inter = number(fields, "scl_inter", 0.0);
    if (sameScaling(slope, inter, how.slope, how.intercept)) {
        h.scl_slope = decltype(h.scl_slope)(slope);
        h.scl_inter = decltype(h.scl_inter)(inter);
    }
    if (!how.geometry)
        notes.push_back("the grid's transform is not the one its NIfTI header gave, so the qform and sform are written from the grid (codes " +
                        std::to_string(h.qform_code) + " and " + std::to_string(h.sform_code) + ")");
    if (!unfit.empty()) {
        std::string names;
        for (const auto& n : unfit) names += (names.empty() ? "" : ", ") + n;
        notes.push_back("NIfTI header fields that do not fit a NIfTI-" + std::string(std::is_same_v<H, nifti_1_header> ? "1" : "2") +
                        " header were not written: " + names);
    }
    return notes;
}

struct FreeDeleter {
    void operator()(void* p) const { std::free(p); }
};
struct ImageDeleter {
    void operator()(nifti_image* n) const { nifti_image_free(n); }
};

} // namespace

std::vector<HeaderField> niftiFieldsOf(const std::string& path) {
    int version = 0;
    std::unique_ptr<void, FreeDeleter> raw(nifti_read_header(path.c_str(), &version, 1));
    if (!raw || (version != 1 && version != 2)) throw Error(path + ": not a readable NIfTI-1 or NIfTI-2 header");
    // libnifti returns the header as stored: a big-endian file's is swapped here.
    const int expected = version == 1 ? 348 : 540;
    if (*static_cast<const int32_t*>(raw.get()) != expected) swap_nifti_header(raw.get(), version);
    if (*static_cast<const int32_t*>(raw.get()) != expected) throw Error(path + ": not a readable NIfTI-1 or NIfTI-2 header (sizeof_hdr)");
    std::vector<HeaderField> out;
    out.push_back({std::string(kPrefix) + "version", int64_t(version)});
    auto keep = [&](const char* name, const auto& field) { out.push_back({std::string(kPrefix) + name, valueOf(field)}); };
    if (version == 1) visitFields(*static_cast<const nifti_1_header*>(raw.get()), keep);
    else visitFields(*static_cast<const nifti_2_header*>(raw.get()), keep);
    std::unique_ptr<nifti_image, ImageDeleter> nim(nifti_image_read(path.c_str(), 0));
    if (nim) {
        for (int i = 0; i < nim->num_ext; ++i) {
            const nifti1_extension& e = nim->ext_list[i];
            const size_t bytes = e.esize > 8 && e.edata ? size_t(e.esize - 8) : 0;
            out.push_back({fmt::format("{}extension_{}_code", kPrefix, i), int64_t(e.ecode)});
            out.push_back({fmt::format("{}extension_{}", kPrefix, i), encodeBase64(std::string_view(e.edata ? e.edata : "", bytes))});
        }
    }
    return out;
}

bool niftiGridTransformOf(const HeaderFieldMap& fields, NiftiGridTransform& out) {
    if (!find(fields, "version")) return false;
    const std::vector<double> pixdim = list(fields, "pixdim");
    if (pixdim.size() != 8) return false;
    nifti_dmat44 m;
    std::memset(&m, 0, sizeof m);
    if (number(fields, "sform_code", 0) > 0) {
        const char* rows[3] = {"srow_x", "srow_y", "srow_z"};
        for (int r = 0; r < 3; ++r) {
            const std::vector<double> row = list(fields, rows[r]);
            if (row.size() != 4) return false;
            for (int c = 0; c < 4; ++c) m.m[r][c] = row[size_t(c)];
        }
    } else if (number(fields, "qform_code", 0) > 0) {
        m = nifti_quatern_to_dmat44(number(fields, "quatern_b", 0.0), number(fields, "quatern_c", 0.0), number(fields, "quatern_d", 0.0),
                                    number(fields, "qoffset_x", 0.0), number(fields, "qoffset_y", 0.0), number(fields, "qoffset_z", 0.0), pixdim[1],
                                    pixdim[2], pixdim[3], pixdim[0] < 0 ? -1.0 : 1.0);
    } else {
        out.lps = false;
        out.origin = {0, 0, 0};
        for (int a = 0; a < 3; ++a) {
            out.axes[size_t(a)] = {0, 0, 0};
            const double d = pixdim[size_t(a + 1)];
            out.axes[size_t(a)][size_t(a)] = d > 0 && std::isfinite(d) ? d : 1.0;
        }
        return true;
    }
    const double flip[3] = {-1, -1, 1};  // RAS -> LPS, as the reader does
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) out.axes[size_t(a)][size_t(c)] = flip[c] * m.m[c][a];
    for (int c = 0; c < 3; ++c) out.origin[size_t(c)] = flip[c] * m.m[c][3];
    out.lps = true;
    return true;
}

std::vector<std::string> restoreNiftiFields(const HeaderFieldMap& fields, const NiftiRestore& how, nifti_1_header& h) {
    return restoreInto(fields, how, h);
}
std::vector<std::string> restoreNiftiFields(const HeaderFieldMap& fields, const NiftiRestore& how, nifti_2_header& h) {
    return restoreInto(fields, how, h);
}

std::vector<std::pair<int, std::string>> niftiExtensionsOf(const HeaderFieldMap& fields) {
    std::vector<std::pair<int, std::string>> out;
    for (int i = 0;; ++i) {
        const HeaderField::Value* code = find(fields, fmt::format("extension_{}_code", i));
        const HeaderField::Value* data = find(fields, fmt::format("extension_{}", i));
        if (!code || !data || !std::holds_alternative<int64_t>(*code) || !std::holds_alternative<std::string>(*data)) break;
        std::optional<std::string> bytes = decodeBase64(std::get<std::string>(*data));
        if (!bytes) break;
        out.emplace_back(int(std::get<int64_t>(*code)), std::move(*bytes));
    }
    return out;
}

} // namespace vdbdag::bridge
