// See LayerScatter.h.
#include "src/pipeline/LayerScatter.h"

#include <algorithm>
#include <optional>

#include <tbb/global_control.h>

#include "src/attributes/WindowCursor.h"
#include "src/encoding/AttributeLayout.h"
#include "src/util/Error.h"

namespace vdbdag::pipeline {

void scatterLayerByCubes(const format::EncodedGrid& grid, bool inactive, unsigned cutLog2, const LayerCubes& visit,
                         const std::function<void(uint64_t, uint64_t)>& progress) {
    const format::EncodedLayer& layer = grid.layer(inactive);
    const encoding::CompactDag& dag = layer.dag;
    if (dag.empty()) return;
    const unsigned vs = valueSize(grid.record.valueType);
    const uint64_t entries = encoding::decodedSize(dag).attributeEntries;
    const std::vector<uint8_t>& attributes = layer.attributes;
    const attributes::ValueWindowsPayload& windows = layer.valueWindows;
    // The values: the attribute array when the reader built it, else the windows.
    std::vector<uint64_t> layout;
    std::vector<coding::BrickPlace> places;
    std::optional<attributes::WindowCursor> cursor;
    if (vs && attributes.empty()) {
        if (windows.empty()) throw Error("grid '" + grid.record.name + "': its " + (inactive ? "inactive" : "active") + " values were not read");
        if (windows.predicted) layout = encoding::attributeLayout(dag), places = encoding::attributePlaces(dag, vs);
        // Windows ahead on the other threads --threads allows (at most 7
        // ahead: each holds up to a window's decoded entries, 16 MB).
        const size_t threads = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
        cursor.emplace(windows.bytes, windows.predicted, vs, layout, "grid '" + grid.record.name + "' value windows", places,
                       unsigned(std::clamp<size_t>(threads, 1, 8) - 1), attributes::referenceWindows(windows.reference, layout, places),
                       windows.referencedBy);
        if (cursor->entries() != entries) throw Error("grid '" + grid.record.name + "': its value windows do not match its DAG");
    } else if (vs && attributes.size() != entries * vs) {
        throw Error("grid '" + grid.record.name + "': its values do not match its DAG");
    }
    const std::vector<encoding::SubtreeInstance> subtrees = encoding::subtreesInAttributeOrder(dag, std::min<unsigned>(cutLog2, dag.log2Size));
    std::vector<uint8_t> values;
    for (size_t i = 0; i < subtrees.size(); ++i) {
        const encoding::SubtreeInstance& s = subtrees[i];
        const uint64_t n = (i + 1 < subtrees.size() ? subtrees[i + 1].firstEntry : entries) - s.firstEntry;
        const uint8_t* at = nullptr;
        if (vs && cursor) {
            values.resize(size_t(n * vs));
            cursor->read(n, values.data());
            at = values.data();
        } else if (vs) {
            at = attributes.data() + s.firstEntry * vs;
        }
        if (visit.begin) visit.begin(s);
        scatterSubtree(dag, s, at, vs, visit.voxels);
        if (visit.end) visit.end();
        if (progress) progress(i + 1, subtrees.size());
    }
}

} // namespace vdbdag::pipeline
