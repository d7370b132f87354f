// Shading choices and value access for renderers; see RenderGrid.h.
#include "src/trace/RenderGrid.h"

#include "src/format/TraceableValues.h"
#include "src/trace/DagTracer.h"
#include "src/util/Error.h"
#include "src/volume/ValueBytes.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>

namespace vdbdag::trace {
namespace {

bool looksLikeColour(std::string name) {
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return name == "cd" || name.find("col") != std::string::npos || name.find("rgb") != std::string::npos;
}

std::array<double, 3> decodeValue(ValueType type, const uint8_t* bytes) { return valueAsDoubles(type, bytes); }

} // namespace

Shading parseShading(const std::string& text) {
    if (text == "auto") return Shading::Auto;
    if (text == "fog") return Shading::Fog;
    if (text == "mip") return Shading::Mip;
    if (text == "labels") return Shading::Labels;
    if (text == "iso") return Shading::Iso;
    if (text == "volume") return Shading::Volume;
    if (text == "slice") return Shading::Slice;
    if (text == "surface") return Shading::Surface;
    if (text == "values") return Shading::Values;
    throw Error("--shading: '" + text + "' is not auto, fog, surface, values, mip, labels, iso, volume or slice");
}

const char* shadingOf(const RenderGrid& grid) {
    return grid.labels ? "labels" : grid.mip ? "mip" : grid.iso ? "iso" : grid.volume ? "volume" : grid.slice ? "slice" : grid.fog ? "fog" : grid.levelSet ? "surface" : "values";
}

RenderGrid makeRenderGrid(const format::EncodedGrid& grid, Shading shading) {
    RenderGrid out;
    out.dag = &grid.active.dag;
    out.valueType = grid.record.valueType;
    out.indexToWorld = grid.record.indexToWorld;
    const bool scalarFloat = out.valueType == ValueType::Float || out.valueType == ValueType::Double;
    if (valueSize(out.valueType) > 0 && grid.active.values.entryCount > 0) {
        out.values = &grid.active.values;
    } else if (valueSize(out.valueType) > 0 && (!grid.active.valueWindows.empty() || !grid.active.attributes.empty())) {
        out.ownValues = std::make_shared<const attributes::PaletteChannel>(format::traceableValues(grid));
        if (out.ownValues->entryCount > 0) out.values = out.ownValues.get();
    }
    // The range of the stored values: the material array and the directly
    // stored values hold every one of them.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    if (out.values) {
        const unsigned vs = out.values->valueSize;
        auto take = [&](const uint8_t* bytes) {
            const double v = decodeValue(out.valueType, bytes)[0];
            if (std::isfinite(v)) { lo = std::min(lo, v); hi = std::max(hi, v); }
        };
        for (size_t i = 0; i + vs <= out.values->materials.size(); i += vs) take(&out.values->materials[i]);
        for (size_t i = 0; i + vs <= out.values->direct.size(); i += vs) take(&out.values->direct[i]);
    }
    const double background = grid.record.background.size() >= valueSize(out.valueType) && valueSize(out.valueType)
                                  ? decodeValue(out.valueType, grid.record.background.data())[0]
                                  : 0.0;
    const bool isLevelSetClass = grid.record.gridClass == "level set";
    switch (shading) {
    case Shading::Auto:
        out.levelSet = isLevelSetClass && scalarFloat;
        out.fog = scalarFloat && !isLevelSetClass &&
                  (grid.record.gridClass == "fog volume" || (out.values && lo >= 0 && background == 0));
        break;
    case Shading::Fog:
        if (!scalarFloat)
            throw Error("grid '" + grid.record.name + "' holds " + valueTypeName(out.valueType) + " values: fog shading needs float or double densities");
        out.fog = true;
        break;
    case Shading::Surface:
        // A level set by class, or by content (a sign change, outside positive).
        out.levelSet = scalarFloat && out.values && (isLevelSetClass || (lo < 0 && background > 0));
        break;
    case Shading::Values: break;
    case Shading::Mip:
    case Shading::Iso:
    case Shading::Volume:
    case Shading::Slice:
        if (valueSize(out.valueType) == 0 || (out.valueType == ValueType::Vec3S || out.valueType == ValueType::Vec3D || out.valueType == ValueType::Vec3I) || out.valueType == ValueType::Bool)
            throw Error("grid '" + grid.record.name + "' holds " + valueTypeName(out.valueType) + " values: " +
                        (shading == Shading::Mip ? "a maximum intensity projection" : shading == Shading::Iso ? "an isosurface" : shading == Shading::Slice ? "a slice" : "volume rendering") +
                        " needs scalar values");
        (shading == Shading::Mip ? out.mip : shading == Shading::Iso ? out.iso : shading == Shading::Slice ? out.slice : out.volume) = true;
        break;
    case Shading::Labels:
        if (out.valueType != ValueType::Int32 && out.valueType != ValueType::Int64)
            throw Error("grid '" + grid.record.name + "' holds " + valueTypeName(out.valueType) + " values: labels are integers");
        out.labels = true;
        out.labelBackground = int64_t(background);
        break;
    }
    if (grid.normals && grid.normals->entryCount() > 0) out.normals = &*grid.normals;
    if (out.levelSet && out.values) out.inside = std::make_shared<const InsideBits>(insideBitsOf(*out.values, out.valueType));
    switch (out.valueType) {
    case ValueType::Vec3I: out.colouring = ValueColouring::Colour; break;
    case ValueType::Vec3S:
    case ValueType::Vec3D: out.colouring = looksLikeColour(grid.record.name) ? ValueColouring::Colour : ValueColouring::Vector; break;
    case ValueType::Float:
    case ValueType::Double:
    case ValueType::Int32:
    case ValueType::Int64: out.colouring = out.levelSet || shading == Shading::Surface ? ValueColouring::None : ValueColouring::Scalar; break;
    default: out.colouring = ValueColouring::None;
    }
    if (!out.values) out.colouring = ValueColouring::None;
    if (out.values && out.colouring == ValueColouring::Scalar && lo <= hi) {
        out.valueMin = lo;
        out.valueMax = hi > lo ? hi : lo + 1;
    }
    if (out.fog && out.values) {
        out.valueMax = std::isfinite(hi) && hi > 0 ? hi : 1;
        out.valueMin = 0;
    }
    if (!grid.active.dag.empty()) {
        const OccupiedBox box = occupiedBox(grid.active.dag, 5);
        for (int a = 0; a < 3; ++a) {
            out.cellLo[a] = double(box.lo[a] + grid.active.dag.origin[a]);
            out.cellHi[a] = double(box.hi[a] + grid.active.dag.origin[a]);
        }
    }
    return out;
}

std::array<double, 3> valueAsDoubles(const RenderGrid& grid, uint64_t attribute) {
    size_t hint = 0;
    return valueAsDoubles(grid, attribute, hint);
}

std::array<double, 3> valueAsDoubles(const RenderGrid& grid, uint64_t attribute, size_t& blockHint) {
    if (!grid.values || attribute >= grid.values->entryCount) return {0, 0, 0};
    uint8_t bytes[24];
    grid.values->lookup(attribute, bytes, blockHint);
    return decodeValue(grid.valueType, bytes);
}

} // namespace vdbdag::trace
