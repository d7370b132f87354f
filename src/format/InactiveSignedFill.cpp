// See InactiveSignedFill.h.
#include "src/format/InactiveSignedFill.h"

#include <bit>
#include <cstring>

#include <vdbdag/dag_access.h>

#include "src/attributes/PredictedWindows.h"
#include "src/dag/DagBuilder.h"
#include "src/encoding/AttributeLayout.h"
#include "src/encoding/CompactDag.h"
#include "src/util/Error.h"
#include "src/volume/SignedFill.h"

namespace vdbdag::format {
namespace {

// The active layer's values in attribute order, in whichever form it holds them.
std::vector<uint8_t> activeValues(const EncodedGrid& grid, uint32_t vs, const attributes::ParallelFor& parallel, const std::string& what) {
    const EncodedLayer& layer = grid.active;
    if (!layer.attributes.empty()) return layer.attributes;
    if (layer.values.entryCount) return layer.values.decodeAll();
    if (layer.valueWindows.empty()) return {};
    if (layer.valueWindows.predicted) {
        const std::vector<uint64_t> layout = encoding::attributeLayout(layer.dag);
        const std::vector<coding::BrickPlace> places = encoding::attributePlaces(layer.dag, vs);
        return attributes::decodePredictedWindows(layer.valueWindows.load(), vs, layout, what + " predicted windows", places, parallel,
                                                  attributes::referenceWindows(layer.valueWindows.reference, layout, places),
                                                  layer.valueWindows.referencedBy.get());
    }
    return attributes::decodeValueWindows(layer.valueWindows.load(), what + " value windows").decodeAll();
}

} // namespace

InactiveLayer signedFillOf(const EncodedGrid& grid, const GridTopology& active, const LayerValues& values, const attributes::ParallelFor& parallel,
                           const std::string& what) {
    std::optional<InactiveLayer> fill = signedFillInactive(active, values, grid.record.valueType, grid.record.background, parallel);
    if (!fill) throw Error(what + ": corrupt (a signed fill for a grid it does not apply to)");
    const uint64_t voxels = fill->topology.activeVoxelCount();
    if (voxels != grid.inactive.voxels)
        throw Error(what + ": corrupt (the signed fill gives " + std::to_string(voxels) + " inactive voxels, the file says " +
                    std::to_string(grid.inactive.voxels) + ")");
    return std::move(*fill);
}

void restoreSignedFill(EncodedGrid& grid, const attributes::ParallelFor& parallel, const std::string& what) {
    const ValueType type = grid.record.valueType;
    const uint32_t vs = valueSize(type);
    // Decoded once: a layer read as windows (ReadOptions::keepValueWindows)
    // keeps them decoded instead, so that its reader does not decode them
    // again (4 bytes a voxel of a float level set in memory).
    if (grid.active.attributes.empty() && !grid.active.valueWindows.empty()) {
        grid.active.attributes = activeValues(grid, vs, parallel, what + " active values");
        grid.active.valueWindows = {};
    }
    std::vector<uint8_t> fromPalette;  // a palette channel's values (a layer read whole holds them as attributes)
    if (grid.active.attributes.empty()) fromPalette = activeValues(grid, vs, parallel, what + " active values");
    const std::vector<uint8_t>& values = grid.active.attributes.empty() ? fromPalette : grid.active.attributes;
    // The active voxels as bricks (spatial masks) with their values in the
    // order of the bricks' bits.
    GridTopology active;
    LayerValues activeBricks;
    activeBricks.bricks.resize(values.size());  // every active value once, in the bricks' bit order
    size_t written = 0;
    bool solid = false;
    encoding::visitInAttributeOrder(
        grid.active.dag,
        [&](const encoding::BrickInstance& b) {
            const uint64_t spatial = b.spatialMask();
            active.bricks.push_back({int32_t(b.x), int32_t(b.y), int32_t(b.z), spatial});
            for (uint64_t bits = spatial; bits; bits &= bits - 1) {
                const int p = std::countr_zero(bits);
                const unsigned stored = access::dagStoredBit(unsigned(p & 3), unsigned((p >> 2) & 3), unsigned(p >> 4), b.mirror);
                const uint64_t entry = b.firstEntry + uint64_t(std::popcount(b.storedMask & ((uint64_t(1) << stored) - 1)));
                if ((entry + 1) * vs > values.size() || written + vs > activeBricks.bricks.size())
                    throw Error(what + ": corrupt (an active voxel without its value)");
                std::memcpy(&activeBricks.bricks[written], &values[size_t(entry) * vs], vs);
                written += vs;
            }
        },
        [&](int64_t, int64_t, int64_t, unsigned, uint64_t) { solid = true; });
    activeBricks.bricks.resize(written);
    if (solid) throw Error(what + ": corrupt (a signed fill for a grid it does not apply to)");
    const InactiveLayer fill = signedFillOf(grid, active, activeBricks, parallel, what);
    EncodedLayer layer;
    layer.voxels = grid.inactive.voxels;  // the fill's count: signedFillOf checked it
    if (!fill.topology.empty()) {
        dag::BuildOptions options;
        options.symmetry = grid.symmetry;
        layer.dag = encoding::encodeCompact(dag::buildDag(fill.topology, options), /*attributeOffsets=*/true);
        const uint64_t n = encoding::decodedSize(layer.dag).attributeEntries;
        layer.attributes.resize(size_t(n) * vs);
        const std::vector<uint8_t>& inside = fill.values.bricks.empty() ? fill.values.tiles : fill.values.bricks;  // -|background| each
        for (uint64_t i = 0; i < n; ++i) std::memcpy(&layer.attributes[size_t(i) * vs], inside.data(), vs);
    }
    grid.inactive = std::move(layer);
}

} // namespace vdbdag::format
