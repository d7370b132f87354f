// See LayerCoding.h.
#include "src/pipeline/LayerCoding.h"

#include <algorithm>
#include <cstring>

#include "src/attributes/PredictedWindows.h"
#include "src/attributes/ValueWindows.h"
#include "src/dag/DagBuilder.h"
#include "src/encoding/AttributeLayout.h"
#include "src/format/SsvdagContainer.h"

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
    out.active.attributes = std::move(coded.attributes);
    out.active.valueWindows = std::move(coded.windows);
    out.lossy = coded.lossy;
    out.colour = std::move(coded.colour);
    out.normals = std::move(coded.normals);
}

void storeInactiveValues(format::EncodedGrid& out, CodedValues&& coded) {
    out.inactive.attributes = std::move(coded.attributes);
    out.inactive.valueWindows = std::move(coded.windows);
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

} // namespace vdbdag::pipeline
