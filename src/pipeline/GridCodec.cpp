// Encode/decode of whole grids in memory: the encode through the one
// encoder (CubeEncoder.h), the decode by scattering each layer's values.
#include "src/pipeline/GridCodec.h"

#include <limits>

#include "src/attributes/PredictedWindows.h"
#include "src/attributes/ScalarTolerance.h"
#include "src/encoding/AttributeLayout.h"
#include "src/format/InactiveSignedFill.h"
#include "src/format/TraceableValues.h"
#include "src/pipeline/AttributeOrder.h"
#include "src/pipeline/CubeEncoder.h"
#include "src/util/ParallelFor.h"

namespace vdbdag::pipeline {

namespace {

// A layer's values in attribute order: as read or gathered, or (a grid just
// encoded whose values were streamed into windows) decoded from its windows.
// `store` holds decoded values when they had to be decoded.
const std::vector<uint8_t>& attributesOf(const format::EncodedGrid& grid, bool inactive, std::vector<uint8_t>& store) {
    const format::EncodedLayer& layer = grid.layer(inactive);
    const std::vector<uint8_t>& attributes = layer.attributes;
    const attributes::ValueWindowsPayload& windows = layer.valueWindows;
    if (!attributes.empty() || windows.empty()) return attributes;
    if (windows.predicted) {
        const encoding::CompactDag& dag = layer.dag;
        const uint32_t vs = valueSize(grid.record.valueType);
        const std::vector<uint64_t> layout = encoding::attributeLayout(dag);
        const std::vector<coding::BrickPlace> places = encoding::attributePlaces(dag, vs);
        store = attributes::decodePredictedWindows(windows.load(), vs, layout, "grid '" + grid.record.name + "' predicted windows", places,
                                                   util::tbbParallelFor(), attributes::referenceWindows(windows.reference, layout, places),
                                                   windows.referencedBy.get());
    }
    else
        store = format::traceableValues(grid, inactive).decodeAll();
    return store;
}

} // namespace

namespace {

// A grid in memory through the one encoder (CubeEncoder.h), sliced into
// cubes; its values in attribute order are kept as the in-memory encode
// always gave them (`info`, `render` and `verify` of a .vdb read them), so
// that a layer streamed into windows is gathered once more. `release`: the
// same grid, non-const, whose voxels are dropped once encoded (nullptr:
// keep them). Without options.keepAttributes, the values in windows only.
format::EncodedGrid encodeGridImpl(const GridRecord& grid, const EncodeOptions& options, GridRecord* release) {
    // The grid is in memory whole: no budget bounds the cubes in flight
    // (each stays within planLayer's own cap) or the windows coded at once
    // (one per core).
    CubeBudget budget;
    budget.bytes = std::numeric_limits<uint64_t>::max() / 4;
    format::EncodedGrid out = encodeGridByCubes(*recordCubes(grid), options, budget);
    const unsigned vs = options.keepAttributes ? valueSize(grid.valueType) : 0;
    // Exact values are gathered again; a lossy layer's come from its windows
    // (the values as stored, not the input's).
    const bool exact = options.tolerance.mode == attributes::ScalarTolerance::Mode::Exact;
    if (vs && out.active.attributes.empty() && !out.active.dag.empty()) {
        if (exact) out.active.attributes = gatherAttributes(out.active.dag, grid.topology, grid.values, vs);
        else {
            std::vector<uint8_t> decoded;
            attributesOf(out, false, decoded);
            out.active.attributes = std::move(decoded);
        }
    }
    if (vs && out.inactive.attributes.empty() && !out.inactive.dag.empty())
        out.inactive.attributes = gatherAttributes(out.inactive.dag, grid.inactiveTopology, grid.inactiveValues, vs);
    if (release) *release = GridRecord{};
    return out;
}

} // namespace

format::EncodedGrid encodeGrid(const GridRecord& grid, const EncodeOptions& options) { return encodeGridImpl(grid, options, nullptr); }


GridRecord decodeGrid(const format::EncodedGrid& grid) {
    GridRecord record = grid.record;
    const unsigned vs = valueSize(grid.record.valueType);
    std::vector<uint8_t> store;
    scatterAttributes(grid.active.dag, attributesOf(grid, false, store), vs, record.topology, record.values);
    store = {};
    if (grid.inactiveSignedFill && grid.inactive.dag.empty()) {  // read without its layer (ReadOptions::signedFillLayer)
        InactiveLayer fill = format::signedFillOf(grid, record.topology, record.values, util::tbbParallelFor(), "grid '" + grid.record.name + "'");
        record.inactiveTopology = std::move(fill.topology);
        record.inactiveValues = std::move(fill.values);
        return record;
    }
    scatterAttributes(grid.inactive.dag, attributesOf(grid, true, store), vs, record.inactiveTopology, record.inactiveValues);
    return record;
}

format::SsvdagScene encodeVolume(const Volume& volume, const EncodeOptions& options, const GridProgress& onGrid) {
    format::SsvdagScene scene;
    scene.fileMetadata = volume.fileMetadata;
    for (size_t g = 0; g < volume.grids.size(); ++g) {
        if (onGrid) onGrid(g, volume.grids.size());
        scene.grids.push_back(encodeGrid(volume.grids[g], options));
    }
    return scene;
}

format::SsvdagScene encodeVolumeReleasing(Volume& volume, const EncodeOptions& options, const GridProgress& onGrid) {
    format::SsvdagScene scene;
    scene.fileMetadata = volume.fileMetadata;
    for (size_t g = 0; g < volume.grids.size(); ++g) {
        if (onGrid) onGrid(g, volume.grids.size());
        scene.grids.push_back(encodeGridImpl(volume.grids[g], options, &volume.grids[g]));
    }
    return scene;
}

Volume decodeScene(const format::SsvdagScene& scene, const GridProgress& onGrid) {
    Volume volume;
    volume.fileMetadata = scene.fileMetadata;
    for (size_t g = 0; g < scene.grids.size(); ++g) {
        if (onGrid) onGrid(g, scene.grids.size());
        volume.grids.push_back(decodeGrid(scene.grids[g]));
    }
    return volume;
}

} // namespace vdbdag::pipeline
