// Encode/decode of whole grids: build + reduce + compact-encode, with the
// root-placement search and the statistics `info` reports.
#include "src/pipeline/GridCodec.h"

#include "src/format/SsvdagContainer.h"

#include <algorithm>
#include <cstring>


#include "src/attributes/PredictedWindows.h"
#include "src/attributes/ValueWindows.h"
#include "src/dag/DagBuilder.h"
#include "src/encoding/AttributeLayout.h"
#include "src/pipeline/AttributeOrder.h"
#include "src/pipeline/GridCodecParts.h"

namespace vdbdag::pipeline {

format::DagStats statsOf(const dag::ReducedDag& reduced) {
    format::DagStats stats;
    stats.svoNodes = reduced.svoNodeCount;
    for (unsigned s = 2; s <= reduced.log2Size; ++s) stats.storedNodes.push_back(reduced.uniqueNodeCount(s));
    return stats;
}

namespace {
int64_t floorDiv(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
} // namespace

// Candidate root origins, best guesses first (DESIGN.md invariant 1: node
// reflections mirror about planes between voxels through node centres, so
// the placement decides which symmetries exist):
//  1. the bounding box's minimum, aligned down;
//  2. centred: the root's centre planes through the box's centre, so a
//     shape symmetric about its own centre is symmetric about the root's;
//  3+. the aligned minimum shifted down by one or more alignment steps along
//     combinations of axes.
std::vector<std::array<int64_t, 3>> placementCandidates(const dag::ActiveBounds& box, int64_t a, int trials) {
    std::array<int64_t, 3> base{}, mid{};
    for (int i = 0; i < 3; ++i) {
        base[i] = floorDiv(box.min[i], a) * a;
        mid[i] = floorDiv(box.min[i] + box.max[i] + 1 + a, 2 * a) * a;  // centre plane, rounded to the alignment
    }
    std::vector<std::array<int64_t, 3>> candidates{base};
    if (trials >= 2) {
        int64_t half = a;
        for (int i = 0; i < 3; ++i)
            while (mid[i] - half > box.min[i] || mid[i] + half <= box.max[i]) half *= 2;
        std::array<int64_t, 3> centred{};
        for (int i = 0; i < 3; ++i) centred[i] = mid[i] - half;
        if (centred != base) candidates.push_back(centred);
    }
    for (int k = 1; int(candidates.size()) < trials && k < 64; ++k) {
        const int64_t step = a * (1 + (k - 1) / 7);
        const unsigned axes = unsigned(1 + (k - 1) % 7);
        candidates.push_back({base[0] - ((axes & 1u) ? step : 0), base[1] - ((axes & 2u) ? step : 0), base[2] - ((axes & 4u) ? step : 0)});
    }
    return candidates;
}

namespace {

// A layer's values at rest: an integer channel (unless --no-predict) in
// predicted windows, each window predicted or palette-coded, whichever is
// smaller; anything else in palette windows.
attributes::ValueWindowsPayload codeValues(const encoding::CompactDag& dag, const std::vector<uint8_t>& attributes, ValueType type,
                                           const EncodeOptions& options) {
    attributes::ValueWindowsPayload out;
    if (usesPredictedWindows(type, options)) {
        out.bytes = attributes::encodePredictedWindows(attributes, valueSize(type), encoding::attributeLayout(dag));
        out.predicted = true;
    } else {
        out.bytes = attributes::encodeValueWindows(attributes, valueSize(type));
    }
    return out;
}

} // namespace

namespace {

// Builds and lays out one layer (active or inactive), trying the placements.
encoding::CompactDag encodeLayer(const GridTopology& topology, const EncodeOptions& options, bool withOffsets, format::DagStats* stats) {
    return encodeAtBestPlacement(dag::activeBounds(topology), dag::placementAlignment(topology), options, withOffsets, stats,
                                 [&](const std::array<int64_t, 3>& origin, bool symmetry) {
                                     dag::BuildOptions build;
                                     build.symmetry = symmetry;
                                     build.origin = origin;
                                     return dag::buildDag(topology, build);
                                 });
}

} // namespace

namespace {

// The inner and leaf sections of `dag` as the file stores them.
uint64_t storedGeometryBytes(const encoding::CompactDag& dag) {
    const std::span<const uint8_t> inner(reinterpret_cast<const uint8_t*>(dag.inner.data()), dag.inner.size() * sizeof(uint16_t));
    const std::span<const uint8_t> leaves(reinterpret_cast<const uint8_t*>(dag.leaves.data()), dag.leaves.size() * sizeof(uint64_t));
    return format::storedSectionBytes(inner) + format::storedSectionBytes(leaves);
}

} // namespace

encoding::CompactDag encodeAtBestPlacement(const dag::ActiveBounds& box, int64_t alignment, const EncodeOptions& options, bool withOffsets,
                                           format::DagStats* stats, const PlacedBuild& build, std::array<int64_t, 3>* keptOrigin) {
    bool first = true;
    std::array<int64_t, 3> kept{0, 0, 0};
    encoding::CompactDag best;
    uint64_t bestStored = 0;
    const auto candidates = placementCandidates(box, alignment, std::max(1, options.placementTrials));
    for (const auto& origin : candidates) {
        const dag::ReducedDag reduced = build(origin, options.symmetry);
        encoding::CompactDag compact = encoding::encodeCompact(reduced, withOffsets, options.compactPointers);
        // The candidate whose geometry takes the fewest bytes in the file:
        // its inner and leaf sections as the writer compresses them (the
        // uncompressed size can rank them the other way).
        const uint64_t stored = candidates.size() == 1 ? 0 : storedGeometryBytes(compact);
        if (first || stored < bestStored || (stored == bestStored && compact.byteSize() < best.byteSize())) {
            bestStored = stored;
            best = std::move(compact);
            if (stats) *stats = statsOf(reduced);
            kept = origin;
        }
        first = false;
    }
    if (stats && options.computeSvdagStats) {
        if (!options.symmetry) {
            stats->svdagNodes = stats->storedNodes;
        } else {
            const dag::ReducedDag plain = build(kept, false);  // same placement, so the per-level counts compare
            for (unsigned s = 2; s <= plain.log2Size; ++s) stats->svdagNodes.push_back(plain.uniqueNodeCount(s));
        }
        stats->hasSvdag = true;
    }
    if (keptOrigin) *keptOrigin = kept;
    return best;
}

format::EncodedGrid encodedHeader(const GridRecord& grid, const EncodeOptions& options) {
    format::EncodedGrid out;
    // The header only: copying the voxels first would double peak memory.
    out.record.name = grid.name;
    out.record.gridClass = grid.gridClass;
    out.record.valueType = grid.valueType;
    out.record.indexToWorld = grid.indexToWorld;
    out.record.vdbDescriptor = grid.vdbDescriptor;
    out.record.background = grid.background;
    out.symmetry = options.symmetry;
    return out;
}

void codeActiveValues(format::EncodedGrid& out, const EncodeOptions& options) {
    const ValueType type = out.record.valueType;
    out.lossy = attributes::applyScalarTolerance(out.attributes, type, options.tolerance);
    if (isColourGrid(out.record, options))
        out.colour = attributes::quantiseColours(out.attributes, type, options.colourBits, "grid '" + out.record.name + "'");
    out.valueWindows = codeValues(out.dag, out.attributes, type, options);
}

void codeInactiveValues(format::EncodedGrid& out, const EncodeOptions& options) {
    out.inactiveValueWindows = codeValues(out.inactiveDag, out.inactiveAttributes, out.record.valueType, options);
}

bool usesPredictedWindows(ValueType type, const EncodeOptions& options) {
    return options.predictIntegers && (type == ValueType::Int32 || type == ValueType::Int64);
}

bool isColourGrid(const GridRecord& grid, const EncodeOptions& options) {
    if (!options.colourBits || !attributes::isVec3Type(grid.valueType)) return false;
    if (options.colourGrids.empty()) return attributes::hasColourGridName(grid.name);
    return std::find(options.colourGrids.begin(), options.colourGrids.end(), grid.name) != options.colourGrids.end();
}

namespace {

// `release`: the same grid, non-const, whose voxels may be dropped once
// they are in attribute order (nullptr: keep them).
format::EncodedGrid encodeGridImpl(const GridRecord& grid, const EncodeOptions& options, GridRecord* release) {
    format::EncodedGrid out = encodedHeader(grid, options);
    const unsigned vs = valueSize(grid.valueType);
    auto step = [&](const char* name) { if (options.onStep) options.onStep(name); };
    out.activeVoxels = grid.topology.activeVoxelCount();
    step("reducing the DAG");
    const bool withNormals = options.normalBits && grid.normals && !grid.topology.empty();
    if (!grid.topology.empty()) out.dag = encodeLayer(grid.topology, options, vs > 0 || withNormals, &out.stats);
    step("ordering values");
    if (!grid.topology.empty()) {
        out.attributes = gatherAttributes(out.dag, grid.topology, grid.values, vs);
        if (release) {
            std::vector<uint8_t>().swap(release->values.bricks);
            std::vector<uint8_t>().swap(release->values.tiles);
        }
    }
    if (withNormals) {
        const std::vector<uint8_t> raw = gatherAttributes(out.dag, grid.topology, grid.normals->vectors, sizeof(std::array<float, 3>));
        std::vector<std::array<float, 3>> exact(raw.size() / sizeof(std::array<float, 3>));
        if (!raw.empty()) std::memcpy(exact.data(), raw.data(), raw.size());
        out.normals = attributes::encodeNormals(exact, options.normalBits,
                                                grid.normals->fromNormalGrid ? attributes::NormalReport::Source::NormalGrid
                                                                             : attributes::NormalReport::Source::Gradient,
                                                grid.normals->oneSided);
    }
    step("palette compression");
    if (!grid.topology.empty()) codeActiveValues(out, options);
    out.inactiveVoxels = grid.inactiveTopology.activeVoxelCount();
    step("inactive values");
    if (!grid.inactiveTopology.empty()) {
        out.inactiveDag = encodeLayer(grid.inactiveTopology, options, vs > 0, nullptr);
        out.inactiveAttributes = gatherAttributes(out.inactiveDag, grid.inactiveTopology, grid.inactiveValues, vs);
        codeInactiveValues(out, options);
    }
    if (release) *release = GridRecord{};  // everything the scene needs is copied
    return out;
}

} // namespace

format::EncodedGrid encodeGrid(const GridRecord& grid, const EncodeOptions& options) { return encodeGridImpl(grid, options, nullptr); }

namespace {

// A layer's values in attribute order: as read or gathered, or (a grid just
// encoded whose values were streamed into windows) decoded from its windows.
// `store` holds decoded values when they had to be decoded.
const std::vector<uint8_t>& attributesOf(const format::EncodedGrid& grid, bool inactive, std::vector<uint8_t>& store) {
    const std::vector<uint8_t>& attributes = inactive ? grid.inactiveAttributes : grid.attributes;
    const attributes::ValueWindowsPayload& windows = inactive ? grid.inactiveValueWindows : grid.valueWindows;
    if (!attributes.empty() || windows.empty()) return attributes;
    if (windows.predicted)
        store = attributes::decodePredictedWindows(windows.load(), valueSize(grid.record.valueType), encoding::attributeLayout(inactive ? grid.inactiveDag : grid.dag),
                                                   "grid '" + grid.record.name + "' predicted windows");
    else
        store = format::traceableValues(grid, inactive).decodeAll();
    return store;
}

} // namespace

GridRecord decodeGrid(const format::EncodedGrid& grid) {
    GridRecord record = grid.record;
    const unsigned vs = valueSize(grid.record.valueType);
    std::vector<uint8_t> store;
    scatterAttributes(grid.dag, attributesOf(grid, false, store), vs, record.topology, record.values);
    store = {};
    scatterAttributes(grid.inactiveDag, attributesOf(grid, true, store), vs, record.inactiveTopology, record.inactiveValues);
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
