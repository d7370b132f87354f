// See GridSummary.h.
#include "src/format/GridSummary.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include <fmt/core.h>

#include "src/attributes/WindowCursor.h"
#include "src/encoding/AttributeLayout.h"
#include "src/util/Error.h"
#include "src/volume/ValueBytes.h"

namespace vdbdag::format {

namespace {

// The summary of `grid` from its DAG (`size`: encoding::decodedSize of it)
// and values, whatever its Summary section says.
GridSummary computedSummary(const EncodedGrid& grid, const encoding::DecodedSize& size) {
    GridSummary s;
    s.activeVoxels = grid.active.voxels;
    s.solidNodes = size.emittedTiles;
    s.indexBox = dagBounds(grid.active.dag);
    const ValueType type = grid.record.valueType;
    const unsigned vs = valueSize(type);
    if (!vs || grid.active.dag.empty()) return s;
    if (grid.active.valueWindows.range) {  // kept by the encoder's value writer
        s.activeRange = *grid.active.valueWindows.range;
        return s;
    }
    if (!grid.active.attributes.empty()) {
        s.activeRange.add(type, grid.active.attributes);
        return s;
    }
    const attributes::ValueWindowsPayload& windows = grid.active.valueWindows;
    if (windows.empty()) {  // a scene read with its palette channel only
        s.activeRange.add(type, grid.active.values.decodeAll());
        return s;
    }
    const std::vector<uint8_t> spilled = windows.file ? windows.load() : std::vector<uint8_t>{};
    const std::span<const uint8_t> bytes = windows.file ? std::span<const uint8_t>(spilled) : std::span<const uint8_t>(windows.bytes);
    const std::string what = "grid '" + grid.record.name + "' value windows";
    if (!windows.predicted) {
        // Every value of a window is one of its materials or stored directly:
        // their range is the window's, and no index is unpacked.
        const attributes::WindowDirectory dir = attributes::readValueWindowDirectory(bytes, what);
        for (size_t k = 0; k < dir.windows.size(); ++k) {
            const attributes::PaletteChannel window = attributes::decodeValueWindow(bytes, dir, k, what);
            s.activeRange.add(type, window.materials);
            s.activeRange.add(type, window.direct);
        }
        return s;
    }
    const std::vector<uint64_t> layout = encoding::attributeLayout(grid.active.dag);
    const std::vector<coding::BrickPlace> places = encoding::attributePlaces(grid.active.dag, vs);
    attributes::WindowCursor cursor(bytes, true, vs, layout, what, places, 0, attributes::referenceWindows(windows.reference, layout, places),
                                    windows.referencedBy);
    constexpr uint64_t kChunk = uint64_t(1) << 16;
    std::vector<uint8_t> chunk;
    for (uint64_t done = 0; done < cursor.entries();) {
        const uint64_t n = std::min(kChunk, cursor.entries() - done);
        chunk.resize(size_t(n * vs));
        cursor.read(n, chunk.data());
        s.activeRange.add(type, chunk);
        done += n;
    }
    return s;
}

} // namespace

GridSummary summarizeGrid(const EncodedGrid& grid) {
    if (!grid.summary) return computedSummary(grid, encoding::decodedSize(grid.active.dag));
    GridSummary s;
    s.activeVoxels = grid.active.voxels;
    s.solidNodes = grid.summary->solidNodes;
    s.indexBox = grid.summary->indexBox;
    s.activeRange = grid.summary->activeRange;
    return s;
}

StoredSummary recomputedSummary(const EncodedGrid& grid) {
    const encoding::DecodedSize active = encoding::decodedSize(grid.active.dag);
    const GridSummary s = computedSummary(grid, active);
    return {s.indexBox, s.solidNodes, active.attributeEntries, (grid.inactiveSignedFill ? 0 : encoding::decodedSize(grid.inactive.dag).attributeEntries), s.activeRange};
}

StoredSummary summaryToStore(const EncodedGrid& grid) { return grid.summary ? *grid.summary : recomputedSummary(grid); }

std::vector<double> valueNumbers(ValueType type, std::span<const uint8_t> value) {
    if (value.size() < valueSize(type)) throw Error("internal error: value too short");
    const std::array<double, 3> d = valueAsDoubles(type, value.data());
    return std::vector<double>(d.begin(), d.begin() + valueComponents(type));
}

std::string formatValue(ValueType type, std::span<const uint8_t> value) {
    if (type == ValueType::Int64) {  // exact, past 2^53
        int64_t v = 0;
        std::memcpy(&v, value.data(), std::min(value.size(), sizeof(v)));
        return std::to_string(v);
    }
    const std::vector<double> n = valueNumbers(type, value);
    if (n.empty()) return "-";
    if (n.size() == 1) return fmt::format("{:.6g}", n[0]);
    return fmt::format("[{:.6g}, {:.6g}, {:.6g}]", n[0], n[1], n[2]);
}

} // namespace vdbdag::format
