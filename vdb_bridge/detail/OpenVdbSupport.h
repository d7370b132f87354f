// Private helpers of vdb_bridge that need OpenVDB types: one-time library
// initialisation, dispatch over the supported grid types, descriptor
// (de)serialisation. Not to be included outside vdb_bridge/ and tests/.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/io/Stream.h>
#include <openvdb/points/PointDataGrid.h>

#include "src/util/Error.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::bridge::detail {

inline void initializeOpenVdb() {
    static std::once_flag once;
    std::call_once(once, [] {
        openvdb::initialize();
    });
}

// One short line: whitespace runs collapsed, at most 300 characters (a
// corrupted file can make OpenVDB quote megabytes of garbage).
inline std::string oneLine(const std::string& s) {
    std::string out;
    for (char c : s) {
        const bool space = c == '\n' || c == '\r' || c == ' ' || c == '\t';
        if (space && (out.empty() || out.back() == ' ')) continue;
        out += space ? ' ' : c;
        if (out.size() >= 300) { out += "..."; break; }
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    return out;
}

// Calls fn(grid, ValueType) with the grid cast to its concrete type; returns
// false for types vdbdag does not convert.
template <typename Fn>
bool dispatchGridType(const openvdb::GridBase& base, Fn&& fn) {
    if (base.isType<openvdb::FloatGrid>()) { fn(static_cast<const openvdb::FloatGrid&>(base), ValueType::Float); return true; }
    if (base.isType<openvdb::DoubleGrid>()) { fn(static_cast<const openvdb::DoubleGrid&>(base), ValueType::Double); return true; }
    if (base.isType<openvdb::Int32Grid>()) { fn(static_cast<const openvdb::Int32Grid&>(base), ValueType::Int32); return true; }
    if (base.isType<openvdb::Int64Grid>()) { fn(static_cast<const openvdb::Int64Grid&>(base), ValueType::Int64); return true; }
    if (base.isType<openvdb::BoolGrid>()) { fn(static_cast<const openvdb::BoolGrid&>(base), ValueType::Bool); return true; }
    if (base.isType<openvdb::MaskGrid>()) { fn(static_cast<const openvdb::MaskGrid&>(base), ValueType::Mask); return true; }
    if (base.isType<openvdb::Vec3SGrid>()) { fn(static_cast<const openvdb::Vec3SGrid&>(base), ValueType::Vec3S); return true; }
    if (base.isType<openvdb::Vec3DGrid>()) { fn(static_cast<const openvdb::Vec3DGrid&>(base), ValueType::Vec3D); return true; }
    if (base.isType<openvdb::Vec3IGrid>()) { fn(static_cast<const openvdb::Vec3IGrid&>(base), ValueType::Vec3I); return true; }
    return false;
}

// The same dispatch over mutable grids: fn(grid).
template <typename Fn>
bool dispatchMutableGridType(openvdb::GridBase& base, Fn&& fn) {
    if (auto* g = dynamic_cast<openvdb::FloatGrid*>(&base)) { fn(*g); return true; }
    if (auto* g = dynamic_cast<openvdb::DoubleGrid*>(&base)) { fn(*g); return true; }
    if (auto* g = dynamic_cast<openvdb::Int32Grid*>(&base)) { fn(*g); return true; }
    if (auto* g = dynamic_cast<openvdb::Int64Grid*>(&base)) { fn(*g); return true; }
    if (auto* g = dynamic_cast<openvdb::BoolGrid*>(&base)) { fn(*g); return true; }
    if (auto* g = dynamic_cast<openvdb::MaskGrid*>(&base)) { fn(*g); return true; }
    if (auto* g = dynamic_cast<openvdb::Vec3SGrid*>(&base)) { fn(*g); return true; }
    if (auto* g = dynamic_cast<openvdb::Vec3DGrid*>(&base)) { fn(*g); return true; }
    if (auto* g = dynamic_cast<openvdb::Vec3IGrid*>(&base)) { fn(*g); return true; }
    return false;
}

inline std::string typeHint(const openvdb::GridBase& base) {
    if (base.isType<openvdb::points::PointDataGrid>()) return " (a PointDataGrid)";
    return "";
}

// The grid stored in a GridRecord's descriptor: an empty grid of the original
// type with its name, class, transform, background and metadata.
inline openvdb::GridBase::Ptr readDescriptor(const std::vector<uint8_t>& bytes, const std::string& what) {
    initializeOpenVdb();
    try {
        std::istringstream in(std::string(bytes.begin(), bytes.end()), std::ios::binary);
        openvdb::io::Stream stream(in);
        openvdb::GridPtrVecPtr grids = stream.getGrids();
        if (!grids || grids->size() != 1) throw Error(what + ": grid descriptor holds no grid");
        return grids->front();
    } catch (const openvdb::Exception& e) {
        throw Error(what + ": grid descriptor is corrupted (" + oneLine(e.what()) + ")");
    } catch (const std::ios_base::failure& e) {
        throw Error(what + ": grid descriptor is corrupted (" + oneLine(e.what()) + ")");
    }
}

// The lattice a float grid's values are believed to lie on
// (GridRecord::rescale): a scan's rescale as DenseImport records it in the
// grid's metadata. None for other grids or unusable numbers.
inline std::optional<ValueRescale> rescaleOf(const openvdb::GridBase& grid) {
    if (!grid.isType<openvdb::FloatGrid>()) return std::nullopt;
    const auto slope = grid.getMetadata<openvdb::DoubleMetadata>("source_rescale_slope");
    const auto intercept = grid.getMetadata<openvdb::DoubleMetadata>("source_rescale_intercept");
    if (!slope) return std::nullopt;
    const ValueRescale r{slope->value(), intercept ? intercept->value() : 0.0};
    if (!std::isfinite(r.slope) || r.slope == 0 || !std::isfinite(r.intercept)) return std::nullopt;
    return r;
}

// OpenVDB's own serialisation of an empty copy of `grid` (metadata,
// transform, background, class, half-float flag): GridRecord::vdbDescriptor.
inline std::vector<uint8_t> descriptorOf(const openvdb::GridBase& grid) {
    openvdb::GridBase::Ptr empty = grid.copyGridWithNewTree();
    std::ostringstream out(std::ios::binary);
    openvdb::io::Stream stream(out);
    stream.setGridStatsMetadataEnabled(false);
    stream.write(openvdb::GridCPtrVec{empty});
    std::string s = out.str();
    // The stream header carries a random UUID (36 ASCII characters after the
    // 8-byte magic, u32 file version, 2 x u32 library version and a flag
    // byte). Fix it so the same input always gives a byte-identical file.
    constexpr size_t kUuidOffset = 21, kUuidLength = 36;
    if (s.size() < kUuidOffset + kUuidLength || s[kUuidOffset + 8] != '-')
        throw Error("internal error: unexpected OpenVDB stream header layout");
    s.replace(kUuidOffset, kUuidLength, "00000000-0000-0000-0000-000000000000");
    return std::vector<uint8_t>(s.begin(), s.end());
}

// The affine index-to-world matrix of a linear transform (identity otherwise).
inline std::array<double, 16> indexToWorldOf(const openvdb::GridBase& grid) {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const auto map = grid.transform().baseMap();
    if (map && map->isLinear()) {
        const openvdb::Mat4d mat = map->getAffineMap()->getMat4();
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) m[size_t(4 * r + c)] = mat(r, c);
    }
    return m;
}

} // namespace vdbdag::bridge::detail
