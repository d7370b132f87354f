// Encode/decode of whole grids: build + reduce + compact-encode, with the
// root-placement search and the statistics `info` reports.
#include "src/pipeline/GridCodec.h"

#include "src/format/GridSummary.h"
#include "src/format/SsvdagContainer.h"
#include "src/format/TraceableValues.h"

#include <algorithm>
#include <cstring>


#include "src/attributes/PredictedWindows.h"
#include "src/attributes/ValueWindows.h"
#include "src/dag/DagBuilder.h"
#include "src/encoding/AttributeLayout.h"
#include "src/pipeline/AttributeOrder.h"
#include "src/pipeline/GridCodecParts.h"
#include "src/util/ParallelFor.h"

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

// A layer's values at rest: an integer or float layer (unless --no-predict;
// floatChannelOf) in predicted windows, each window predicted or
// palette-coded, whichever is smaller; anything else in palette windows.
attributes::ValueWindowsPayload codeValues(const encoding::CompactDag& dag, const std::vector<uint8_t>& attributes, const GridRecord& header,
                                           const EncodeOptions& options, bool inactive) {
    attributes::ValueWindowsPayload out;
    const ValueType type = header.valueType;
    if (usesPredictedWindows(header, options, inactive)) {
        out.bytes = attributes::encodePredictedWindows(attributes, valueSize(type), encoding::attributeLayout(dag),
                                                       encoding::attributePlaces(dag, valueSize(type)), floatChannelOf(header, options, inactive));
        out.predicted = true;
    } else {
        out.bytes = attributes::encodeValueWindows(attributes, valueSize(type));
    }
    return out;
}

} // namespace

namespace {

// Builds and lays out one layer (active or inactive), trying the placements.
encoding::CompactDag encodeLayer(const GridTopology& topology, const EncodeOptions& options, bool withOffsets, format::DagStats* stats,
                                 const CandidateValues& values) {
    return encodeAtBestPlacement(
        dag::activeBounds(topology), dag::placementAlignment(topology), options, withOffsets, stats,
        [&](const std::array<int64_t, 3>& origin, bool symmetry) {
            dag::BuildOptions build;
            build.symmetry = symmetry;
            build.origin = origin;
            return dag::buildDag(topology, build);
        },
        &values);
}

} // namespace

namespace {

// The level table, inner and leaf sections of `dag` as the file stores them.
uint64_t storedGeometryBytes(const encoding::CompactDag& dag) {
    const std::span<const uint8_t> inner(reinterpret_cast<const uint8_t*>(dag.inner.data()), dag.inner.size() * sizeof(uint16_t));
    const std::span<const uint8_t> leaves(reinterpret_cast<const uint8_t*>(dag.leaves.data()), dag.leaves.size() * sizeof(uint64_t));
    return format::storedSectionBytes(format::serializeDagLevels(dag)) + format::storedSectionBytes(inner) + format::storedSectionBytes(leaves);
}

// The plain SVDAG's node counts beside `stats` (options.computeSvdagStats):
// the same placement without symmetry, so the per-level counts compare.
void addSvdagStats(format::DagStats& stats, const PlacedBuild& build, const std::array<int64_t, 3>& origin, const EncodeOptions& options) {
    if (!options.symmetry) {
        stats.svdagNodes = stats.storedNodes;
    } else {
        const dag::ReducedDag plain = build(origin, false);
        for (unsigned s = 2; s <= plain.log2Size; ++s) stats.svdagNodes.push_back(plain.uniqueNodeCount(s));
    }
    stats.hasSvdag = true;
}

} // namespace

encoding::CompactDag encodeAtBestPlacement(const dag::ActiveBounds& box, int64_t alignment, const EncodeOptions& options, bool withOffsets,
                                           format::DagStats* stats, const PlacedBuild& build, const CandidateValues* values) {
    bool first = true;
    std::array<int64_t, 3> kept{0, 0, 0};
    encoding::CompactDag best;
    uint64_t bestStored = 0;
    const auto candidates = placementCandidates(box, alignment, std::max(1, options.placementTrials));
    const bool several = candidates.size() > 1;
    for (const auto& origin : candidates) {
        const dag::ReducedDag reduced = build(origin, options.symmetry);
        encoding::CompactDag compact = encoding::encodeCompact(reduced, withOffsets, options.compactPointers);
        // With several candidates, the one whose file is smallest: every
        // section the placement changes, as the writer stores it (the
        // uncompressed sizes can rank them the other way). With one, nothing
        // is measured.
        format::DagStats candidateStats;
        if (stats) candidateStats = statsOf(reduced);
        uint64_t stored = 0;
        if (several) {
            stored = storedGeometryBytes(compact);
            if (stats && options.computeSvdagStats) addSvdagStats(candidateStats, build, origin, options);
            if (stats) stored += format::storedSectionBytes(format::serializeDagStats(candidateStats));
        }
        if (values) stored += values->code(compact, origin);
        if (first || stored < bestStored || (stored == bestStored && compact.byteSize() < best.byteSize())) {
            bestStored = stored;
            best = std::move(compact);
            if (stats) *stats = std::move(candidateStats);
            kept = origin;
            if (values) values->keep();
        }
        first = false;
    }
    if (stats && options.computeSvdagStats && !several) addSvdagStats(*stats, build, kept, options);
    return best;
}

format::EncodedGrid encodedHeader(const GridRecord& grid, const EncodeOptions& options) {
    format::EncodedGrid out;
    // The header only: copying the voxels first would double peak memory.
    out.record = headerOf(grid);
    out.symmetry = options.symmetry;
    return out;
}

uint64_t CodedValues::storedBytes() const {
    uint64_t bytes = windows.size();
    if (normals) bytes += format::storedSectionBytes(attributes::serializeNormals(*normals));
    return bytes;
}

void codeActiveValues(const encoding::CompactDag& dag, CodedValues& coded, const GridRecord& header, const EncodeOptions& options) {
    const ValueType type = header.valueType;
    coded.lossy = attributes::applyScalarTolerance(coded.attributes, type, options.tolerance);
    if (isColourGrid(header, options))
        coded.colour = attributes::quantiseColours(coded.attributes, type, options.colourBits, "grid '" + header.name + "'");
    coded.windows = codeValues(dag, coded.attributes, header, options, false);
}

void codeInactiveValues(const encoding::CompactDag& dag, CodedValues& coded, const GridRecord& header, const EncodeOptions& options) {
    coded.windows = codeValues(dag, coded.attributes, header, options, true);
}

void storeActiveValues(format::EncodedGrid& out, CodedValues&& coded) {
    out.attributes = std::move(coded.attributes);
    out.valueWindows = std::move(coded.windows);
    out.lossy = coded.lossy;
    out.colour = std::move(coded.colour);
    out.normals = std::move(coded.normals);
}

void storeInactiveValues(format::EncodedGrid& out, CodedValues&& coded) {
    out.inactiveAttributes = std::move(coded.attributes);
    out.inactiveValueWindows = std::move(coded.windows);
}

std::optional<attributes::FloatChannel> floatChannelOf(const GridRecord& grid, const EncodeOptions& options, bool inactive) {
    if (!options.predictIntegers) return std::nullopt;
    // A vec3s layer (velocities; colours have their own quantiser) is kept
    // exactly whatever the tolerance (ScalarTolerance.h): its components' bits.
    if (grid.valueType == ValueType::Vec3S) return inactive || isColourGrid(grid, options) ? std::nullopt : std::optional(attributes::FloatChannel{});
    if (grid.valueType != ValueType::Float) return std::nullopt;
    using Mode = attributes::ScalarTolerance::Mode;
    switch (options.tolerance.mode) {
    case Mode::Exact:
        if (inactive && !grid.rescale) return std::nullopt;
        return attributes::FloatChannel{grid.rescale};
    case Mode::Absolute:  // the quantiser rounds to float(k x 2E): a lattice (values it keeps exact are exceptions)
        if (inactive) return std::nullopt;  // never lossy
        return attributes::FloatChannel{ValueRescale{2.0 * options.tolerance.bound, 0.0}};
    case Mode::Relative:  // a logarithmic grid: the float coder or palettes
        if (inactive) return std::nullopt;
        return attributes::FloatChannel{};
    }
    return std::nullopt;
}

bool usesPredictedWindows(const GridRecord& grid, const EncodeOptions& options, bool inactive) {
    return (options.predictIntegers && (grid.valueType == ValueType::Int32 || grid.valueType == ValueType::Int64)) ||
           floatChannelOf(grid, options, inactive);
}

bool isColourGrid(const GridRecord& grid, const EncodeOptions& options) {
    if (!options.colourBits || !attributes::isVec3Type(grid.valueType)) return false;
    if (options.colourGrids.empty()) return attributes::hasColourGridName(grid.name);
    return std::find(options.colourGrids.begin(), options.colourGrids.end(), grid.name) != options.colourGrids.end();
}

namespace {

// The grid's exact normals (GridRecord::normals) in `dag`'s attribute order, as ONVs.
attributes::NormalChannel normalsOf(const encoding::CompactDag& dag, const GridRecord& grid, const EncodeOptions& options) {
    const std::vector<uint8_t> raw = gatherAttributes(dag, grid.topology, grid.normals->vectors, sizeof(std::array<float, 3>));
    std::vector<std::array<float, 3>> exact(raw.size() / sizeof(std::array<float, 3>));
    if (!raw.empty()) std::memcpy(exact.data(), raw.data(), raw.size());
    return attributes::encodeNormals(exact, options.normalBits,
                                     grid.normals->fromNormalGrid ? attributes::NormalReport::Source::NormalGrid : attributes::NormalReport::Source::Gradient,
                                     grid.normals->oneSided);
}

// `release`: the same grid, non-const, whose voxels may be dropped once
// they are in attribute order (nullptr: keep them).
format::EncodedGrid encodeGridImpl(const GridRecord& grid, const EncodeOptions& options, GridRecord* release) {
    format::EncodedGrid out = encodedHeader(grid, options);
    const unsigned vs = valueSize(grid.valueType);
    auto step = [&](const char* name) { if (options.onStep) options.onStep(name); };
    out.activeVoxels = grid.topology.activeVoxelCount();
    step("reducing the DAG");
    const bool withNormals = options.normalBits && grid.normals && !grid.topology.empty();
    // Each placement candidate's values are gathered and coded (the
    // placement orders them); the smallest file's are kept.
    CodedValues kept, trial;
    const CandidateValues active{[&](const encoding::CompactDag& dag, const std::array<int64_t, 3>&) {
                                     trial = {};
                                     step("ordering values");
                                     trial.attributes = gatherAttributes(dag, grid.topology, grid.values, vs);
                                     if (withNormals) trial.normals = normalsOf(dag, grid, options);
                                     step("palette compression");
                                     codeActiveValues(dag, trial, grid, options);
                                     return trial.storedBytes();
                                 },
                                 [&] { kept = std::move(trial); }};
    if (!grid.topology.empty()) {
        out.dag = encodeLayer(grid.topology, options, vs > 0 || withNormals, &out.stats, active);
        storeActiveValues(out, std::move(kept));
        trial = {};
        if (release) {
            std::vector<uint8_t>().swap(release->values.bricks);
            std::vector<uint8_t>().swap(release->values.tiles);
        }
    }
    out.inactiveVoxels = grid.inactiveTopology.activeVoxelCount();
    step("inactive values");
    if (!grid.inactiveTopology.empty()) {
        const CandidateValues inactive{[&](const encoding::CompactDag& dag, const std::array<int64_t, 3>&) {
                                           trial = {};
                                           trial.attributes = gatherAttributes(dag, grid.inactiveTopology, grid.inactiveValues, vs);
                                           codeInactiveValues(dag, trial, grid, options);
                                           return trial.storedBytes();
                                       },
                                       [&] { kept = std::move(trial); }};
        out.inactiveDag = encodeLayer(grid.inactiveTopology, options, vs > 0, nullptr, inactive);
        storeInactiveValues(out, std::move(kept));
    }
    if (release) *release = GridRecord{};  // everything the scene needs is copied
    out.summary = format::summaryToStore(out);
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
    if (windows.predicted) {
        const encoding::CompactDag& dag = inactive ? grid.inactiveDag : grid.dag;
        const uint32_t vs = valueSize(grid.record.valueType);
        store = attributes::decodePredictedWindows(windows.load(), vs, encoding::attributeLayout(dag), "grid '" + grid.record.name + "' predicted windows",
                                                   encoding::attributePlaces(dag, vs), util::tbbParallelFor());
    }
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
