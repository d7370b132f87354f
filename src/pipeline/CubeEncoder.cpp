// See CubeEncoder.h.
#include "src/pipeline/CubeEncoder.h"

#include <algorithm>
#include <cstring>
#include <functional>
#include <optional>
#include <type_traits>

#include <tbb/info.h>
#include <tbb/parallel_pipeline.h>

#include "src/attributes/PredictedWindows.h"
#include "src/attributes/ScalarTolerance.h"
#include "src/attributes/ValueWindows.h"
#include "src/dag/ReducedDagBytes.h"
#include "src/dag/SubDagMerge.h"
#include "src/encoding/CompactDag.h"
#include "src/format/GridSummary.h"
#include "src/format/SsvdagContainer.h"
#include "src/pipeline/AttributeOrder.h"
#include "src/pipeline/LayerCoding.h"
#include "src/util/Error.h"

namespace vdbdag::pipeline {
namespace {

struct LayerPlan {
    dag::RootPlacement placement;
    unsigned cubeLog2;
    std::vector<CubeLoad> cubes;  // Morton order
};

dag::ActiveBounds boxOf(const LayerSummary& summary) { return {summary.min, summary.max}; }

unsigned workersOf(const CubeBudget& budget) {
    return budget.workers ? budget.workers : unsigned(std::max(1, tbb::info::default_concurrency()));
}

// The largest cube size whose busiest cube fits a worker's share of the budget.
LayerPlan planLayer(CubeSource& source, Layer layer, const dag::RootPlacement& placement, const CubeBudget& budget, unsigned valueSize) {
    // Small cubes even with memory to spare: they keep the cores busy and
    // the working set in cache-friendly pieces; the merge costs little.
    constexpr uint64_t kLargestCube = uint64_t(64) << 20;
    const uint64_t share = std::clamp<uint64_t>(budget.bytes / workersOf(budget), 1, kLargestCube);
    const unsigned smallest = std::min(placement.log2Size, 3u);
    unsigned log2 = budget.cubeLog2 ? std::clamp(*budget.cubeLog2, smallest, placement.log2Size) : placement.log2Size;
    for (;;) {
        std::vector<CubeLoad> cubes = source.cubes(layer, placement.origin, log2);
        uint64_t busiest = 0;
        for (const CubeLoad& c : cubes) busiest = std::max(busiest, c.bricks);
        if (budget.cubeLog2 || log2 <= smallest || busiest * cubeBytesPerBrick(valueSize) <= share) {
            std::sort(cubes.begin(), cubes.end(), [](const CubeLoad& a, const CubeLoad& b) {
                return dag::mortonLess({a.cell.x, a.cell.y, a.cell.z}, {b.cell.x, b.cell.y, b.cell.z});
            });
            return {placement, log2, std::move(cubes)};
        }
        --log2;
    }
}

std::array<int64_t, 3> cornerOf(const LayerPlan& plan, const CubeCell& cell) {
    const auto& o = plan.placement.origin;
    return {o[0] + (int64_t(cell.x) << plan.cubeLog2), o[1] + (int64_t(cell.y) << plan.cubeLog2), o[2] + (int64_t(cell.z) << plan.cubeLog2)};
}

// The cell of the cube whose minimum corner is (x, y, z).
CubeCell cellAt(const LayerPlan& plan, int64_t x, int64_t y, int64_t z) {
    const auto& o = plan.placement.origin;
    return {uint32_t(uint64_t(x - o[0]) >> plan.cubeLog2), uint32_t(uint64_t(y - o[1]) >> plan.cubeLog2), uint32_t(uint64_t(z - o[2]) >> plan.cubeLog2)};
}

// Items [begin, end) through three stages, at most `workers` in flight:
// read(piece) in order (a CubeSource is read by one thread at a time),
// work(piece) on any worker, done(piece) in order.
template <typename Piece, typename Read, typename Work, typename Done>
void throughCubes(const CubeBudget& budget, size_t begin, size_t end, Read&& read, Work&& work, Done&& done) {
    size_t next = begin;
    tbb::parallel_pipeline(
        workersOf(budget),
        tbb::make_filter<void, std::shared_ptr<Piece>>(tbb::filter_mode::serial_in_order,
                                                       [&](tbb::flow_control& fc) -> std::shared_ptr<Piece> {
                                                           if (next == end) { fc.stop(); return nullptr; }
                                                           auto piece = std::make_shared<Piece>();
                                                           piece->index = next++;
                                                           read(*piece);
                                                           return piece;
                                                       }) &
            tbb::make_filter<std::shared_ptr<Piece>, std::shared_ptr<Piece>>(tbb::filter_mode::parallel,
                                                                             [&](std::shared_ptr<Piece> piece) {
                                                                                 work(*piece);
                                                                                 return piece;
                                                                             }) &
            tbb::make_filter<std::shared_ptr<Piece>, void>(tbb::filter_mode::serial_in_order, [&](std::shared_ptr<Piece> piece) { done(*piece); }));
}

using StepProgress = std::function<void(uint64_t done, uint64_t total)>;

// Sub-DAGs of cubes [begin, end) of the plan, built several at a time;
// `onSub(index, sub)` runs in cube order.
void buildSubDags(CubeSource& source, const LayerPlan& plan, bool symmetry, const CubeBudget& budget, size_t begin, size_t end,
                  const std::function<void(size_t, dag::ReducedDag&)>& onSub, const StepProgress& progress) {
    struct Piece {
        size_t index;
        GridTopology topology;
        dag::ReducedDag sub;
    };
    throughCubes<Piece>(
        budget, begin, end,
        [&](Piece& piece) {
            LayerValues none;
            source.read(plan.cubes[piece.index].cell, piece.topology, none);
        },
        [&](Piece& piece) {
            dag::BuildOptions options;
            options.symmetry = symmetry;
            options.log2Size = plan.cubeLog2;
            options.origin = cornerOf(plan, plan.cubes[piece.index].cell);
            piece.sub = dag::buildDag(piece.topology, options);
            piece.topology = {};
        },
        [&](Piece& piece) {
            onSub(piece.index, piece.sub);
            if (progress) progress(piece.index + 1 - begin, end - begin);
        });
}

// Builds the layer's DAG from its cubes (geometry only). With several
// processes each builds the sub-DAGs of its share of the cubes and process
// 0 merges them; every process gets the merged DAG.
dag::ReducedDag buildLayer(CubeSource& source, Layer layer, const LayerPlan& plan, bool symmetry, const CubeBudget& budget, CubeTeam& team,
                           const StepProgress& progress) {
    if (plan.cubeLog2 >= plan.placement.log2Size) {  // one cube: the whole layer, on process 0
        std::vector<uint8_t> bytes;
        if (team.isRoot()) {
            dag::BuildOptions whole;
            whole.symmetry = symmetry;
            whole.origin = plan.placement.origin;
            whole.log2Size = plan.cubeLog2;
            GridTopology topology;
            LayerValues none;
            source.beginPass(layer, plan.placement.origin, plan.cubeLog2, false);
            source.read({0, 0, 0}, topology, none);
            source.endPass();
            const dag::ReducedDag dag = dag::buildDag(topology, whole);
            if (team.size() == 1) return dag;
            dag::appendReducedDag(dag, bytes);
        }
        bytes = team.broadcast(bytes);
        size_t pos = 0;
        return dag::readReducedDag(bytes, pos);
    }
    std::vector<uint64_t> weights;
    for (const CubeLoad& c : plan.cubes) weights.push_back(c.bricks);
    const std::vector<size_t> shares = splitByWeight(weights, team.size());
    std::optional<dag::SubDagMerger> merger;
    if (team.isRoot()) merger.emplace(plan.placement, plan.cubeLog2, symmetry);
    auto addToMerger = [&](size_t index, const dag::ReducedDag& sub) {
        const CubeCell& c = plan.cubes[index].cell;
        merger->add({c.x, c.y, c.z}, sub);
    };
    source.beginPass(layer, plan.placement.origin, plan.cubeLog2, false);
    std::vector<uint8_t> mine;
    buildSubDags(source, plan, symmetry, budget, shares[team.rank()], shares[team.rank() + 1], [&](size_t index, dag::ReducedDag& sub) {
        if (team.size() == 1) addToMerger(index, sub);
        else dag::appendReducedDag(sub, mine);
    }, progress);
    source.endPass();
    if (team.size() > 1) {
        const std::vector<std::vector<uint8_t>> all = team.gather(mine);
        std::vector<uint8_t>().swap(mine);
        if (team.isRoot())
            for (unsigned r = 0; r < team.size(); ++r) {
                size_t pos = 0;
                for (size_t index = shares[r]; index < shares[r + 1]; ++index) addToMerger(index, dag::readReducedDag(all[r], pos));
            }
    }
    std::vector<uint8_t> bytes;
    if (team.isRoot()) {
        GridTopology large;
        LayerValues none;
        source.largeTiles(layer, plan.cubeLog2, large, none);
        std::vector<std::pair<dag::CellCoord, unsigned>> largeTiles;
        for (const Tile& t : large.tiles) {
            const auto& o = plan.placement.origin;
            largeTiles.push_back({{uint32_t(uint64_t(t.x - o[0]) >> t.log2Size), uint32_t(uint64_t(t.y - o[1]) >> t.log2Size),
                                   uint32_t(uint64_t(t.z - o[2]) >> t.log2Size)},
                                  t.log2Size});
        }
        dag::ReducedDag merged = merger->finish(largeTiles);
        if (team.size() == 1) return merged;
        dag::appendReducedDag(merged, bytes);
    }
    bytes = team.broadcast(bytes);
    size_t pos = 0;
    return dag::readReducedDag(bytes, pos);
}

// Where a streamed layer's values go: palette windows, or (integers)
// predicted windows, which take each subtree's brick layout too.
struct ValueStream {
    attributes::ValueWindowWriter* palette = nullptr;
    attributes::PredictedWindowWriter* predicted = nullptr;
    attributes::ScalarQuantizer* quantizer = nullptr;  // lossy: each subtree's values quantised in attribute order
    attributes::NormalQuantizer* normals = nullptr;    // normals: quantised as gathered (in parallel), added in order
};

// The layer's values in attribute order, cube by cube. With several
// processes each gathers a contiguous share of the subtrees and process 0
// receives them; elsewhere the result is empty. With `stream` (one process
// only) each subtree's values go to it in order as they are gathered and
// the result is empty: the layer's values are never held whole.
std::vector<uint8_t> gatherLayer(CubeSource& source, Layer layer, const LayerPlan& plan, const encoding::CompactDag& dag, unsigned vs,
                                 const CubeBudget& budget, CubeTeam& team, const StepProgress& progress, ValueStream* stream = nullptr) {
    if (vs == 0 || dag.empty()) return {};
    const uint64_t entries = encoding::decodedSize(dag).attributeEntries;
    const unsigned cut = std::min<unsigned>(plan.cubeLog2, dag.log2Size);
    const std::vector<encoding::SubtreeInstance> subtrees = encoding::subtreesInAttributeOrder(dag, cut);
    std::vector<uint64_t> weights;
    for (size_t i = 0; i < subtrees.size(); ++i) weights.push_back((i + 1 < subtrees.size() ? subtrees[i + 1].firstEntry : entries) - subtrees[i].firstEntry);
    const std::vector<size_t> shares = splitByWeight(weights, team.size());
    const size_t begin = shares[team.rank()], end = shares[team.rank() + 1];
    const uint64_t firstEntry = begin < subtrees.size() ? subtrees[begin].firstEntry : entries;
    const uint64_t endEntry = end < subtrees.size() ? subtrees[end].firstEntry : entries;
    // This process's entries, [firstEntry, endEntry); process 0 of a solo
    // team fills the whole array directly (unless it streams them).
    // Several processes streaming: each codes the windows of its share.
    if (stream && team.size() != 1) {
        if (stream->predicted) stream->predicted->beginShare(firstEntry, endEntry == entries);
        else stream->palette->beginShare(firstEntry, endEntry == entries);
    }
    std::vector<uint8_t> attributes(stream ? 0 : (endEntry - firstEntry) * vs);
    auto entriesOf = [&](size_t i) { return (i + 1 < subtrees.size() ? subtrees[i + 1].firstEntry : entries) - subtrees[i].firstEntry; };
    GridTopology largeTopology;
    LayerValues largeValues;
    source.largeTiles(layer, plan.cubeLog2, largeTopology, largeValues);
    source.beginPass(layer, plan.placement.origin, plan.cubeLog2, true);
    struct Piece {
        size_t index;
        GridTopology topology;
        LayerValues values;
        std::vector<uint8_t> gathered;  // streaming: the subtree's entries
        std::vector<uint64_t> layout;   // ... and their bricks, for predicted windows
        std::vector<coding::BrickPlace> places;  // ... and where they lie (int32)
    };
    throughCubes<Piece>(
        budget, begin, end,
        [&](Piece& piece) {
            const encoding::SubtreeInstance& s = subtrees[piece.index];
            if (s.log2Size <= plan.cubeLog2) source.read(cellAt(plan, s.x, s.y, s.z), piece.topology, piece.values);
        },
        [&](Piece& piece) {
            const encoding::SubtreeInstance& s = subtrees[piece.index];
            const bool large = s.log2Size > plan.cubeLog2;
            if (stream) {
                piece.gathered.resize(entriesOf(piece.index) * vs);
                gatherSubtree(dag, s, large ? largeTopology : piece.topology, large ? largeValues : piece.values, vs, piece.gathered.data(), s.firstEntry,
                              stream->predicted ? &piece.layout : nullptr, stream->predicted && (vs == 4 || vs == 12) ? &piece.places : nullptr);
                if (stream->normals) stream->normals->quantise(piece.gathered);
            } else {
                gatherSubtree(dag, s, large ? largeTopology : piece.topology, large ? largeValues : piece.values, vs, attributes.data(), firstEntry);
            }
            piece.topology = {};
            piece.values = {};
        },
        [&](Piece& piece) {
            if (stream && stream->quantizer) stream->quantizer->apply(piece.gathered);
            if (stream && stream->predicted) stream->predicted->add(piece.gathered, piece.layout, piece.places);
            else if (stream && stream->palette) stream->palette->add(piece.gathered);
            else if (stream && stream->normals) stream->normals->add(piece.gathered);
            piece.gathered = {};
            piece.layout = {};
            piece.places = {};
            if (progress) progress(piece.index + 1 - begin, end - begin);
        });
    source.endPass();
    if (team.size() == 1 || stream) return attributes;
    const std::vector<std::vector<uint8_t>> all = team.gather(attributes);
    if (!team.isRoot()) return {};
    std::vector<uint8_t> whole;
    whole.reserve(entries * vs);
    for (const auto& part : all) whole.insert(whole.end(), part.begin(), part.end());
    if (whole.size() != entries * vs) throw Error("internal error: the processes' values do not add up to the DAG's entries");
    return whole;
}

// A layer's values coded at one candidate (its DAG and plan); returns their
// stored bytes (on process 0; elsewhere anything).
using PlanValues = std::function<uint64_t(const encoding::CompactDag& dag, const LayerPlan& plan)>;

// The level table, inner and leaf sections of `dag` as the file stores them.
uint64_t storedGeometryBytes(const encoding::CompactDag& dag) {
    const std::vector<uint16_t> words = encoding::innerWordsAtRest(dag);
    const std::span<const uint8_t> inner(reinterpret_cast<const uint8_t*>(words.data()), words.size() * sizeof(uint16_t));
    const std::span<const uint8_t> leaves(reinterpret_cast<const uint8_t*>(dag.leaves.data()), dag.leaves.size() * sizeof(uint64_t));
    return format::storedSectionBytes(format::serializeDagLevels(dag)) + format::storedSectionBytes(inner) + format::storedSectionBytes(leaves);
}

// Builds the layer at each root placement candidate (placementCandidates)
// and keeps the one whose file is smallest: its geometry as the writer
// compresses it plus its values, coded by `code` in that candidate's
// attribute order (the placement orders the values, so it changes their
// coding too); `keep()` runs right after `code` for a candidate that is the
// best so far, to keep what was just coded. With one candidate nothing is
// measured. With `stats`, the kept DAG's node counts, and the plain SVDAG's
// (the same placement without symmetry) when options.computeSvdagStats.
encoding::CompactDag encodeLayerByCubes(CubeSource& source, Layer layer, const EncodeOptions& options, const CubeBudget& budget, bool withOffsets,
                                        format::DagStats* stats, CubeTeam& team, const PlanValues& code, const std::function<void()>& keep) {
    const LayerSummary summary = source.summary(layer);
    const dag::ActiveBounds box = boxOf(summary);
    const int64_t alignment = int64_t(1) << std::max(2u, summary.largestTileLog2);
    const unsigned vs = valueSize(source.header().valueType);
    const auto planAt = [&](const std::array<int64_t, 3>& origin) {
        dag::BuildOptions build;
        build.origin = origin;
        return planLayer(source, layer, dag::placeRoot(box, alignment, build), budget, vs);
    };
    // The plain SVDAG's node counts at a placement, beside `candidate`'s.
    const auto addSvdagStats = [&](format::DagStats& candidate, const LayerPlan& plan) {
        if (!options.symmetry) {
            candidate.svdagNodes = candidate.storedNodes;
        } else {
            const dag::ReducedDag plain = buildLayer(source, layer, plan, false, budget, team, options.onStepProgress);
            for (unsigned s = 2; s <= plain.log2Size; ++s) candidate.svdagNodes.push_back(plain.uniqueNodeCount(s));
        }
        candidate.hasSvdag = true;
    };
    // Every process keeps the same candidate: process 0's figure decides.
    const auto agreed = [&](uint64_t stored) {
        if (team.size() == 1) return stored;
        std::vector<uint8_t> bytes(sizeof stored);
        std::memcpy(bytes.data(), &stored, sizeof stored);
        bytes = team.broadcast(bytes);
        uint64_t figure = 0;
        std::memcpy(&figure, bytes.data(), sizeof figure);
        return figure;
    };
    const auto candidates = placementCandidates(box, alignment, std::max(1, options.placementTrials));
    const bool several = candidates.size() > 1;
    std::optional<LayerPlan> keptPlan;
    encoding::CompactDag best;
    uint64_t bestStored = 0;
    for (const auto& origin : candidates) {
        LayerPlan plan = planAt(origin);
        const dag::ReducedDag reduced = buildLayer(source, layer, plan, options.symmetry, budget, team, options.onStepProgress);
        encoding::CompactDag compact = encoding::encodeCompact(reduced, withOffsets, options.compactPointers);
        // With several candidates, every section the placement changes, as
        // the writer stores it (the uncompressed sizes can rank them the
        // other way).
        format::DagStats candidateStats;
        if (stats) candidateStats = statsOf(reduced);
        uint64_t stored = 0;
        if (several) {
            stored = storedGeometryBytes(compact);
            if (stats && options.computeSvdagStats) addSvdagStats(candidateStats, plan);
            if (stats) stored += format::storedSectionBytes(format::serializeDagStats(candidateStats));
        }
        stored += agreed(code(compact, plan));
        if (!keptPlan || stored < bestStored || (stored == bestStored && compact.byteSize() < best.byteSize())) {
            bestStored = stored;
            best = std::move(compact);
            if (stats) *stats = std::move(candidateStats);
            keptPlan = std::move(plan);
            keep();
        }
    }
    if (stats && options.computeSvdagStats && !several) addSvdagStats(*stats, *keptPlan);
    return best;
}

} // namespace

uint64_t cubeBytesPerBrick(unsigned valueSize) { return 160 + 64ull * valueSize; }

unsigned valueWindowsInFlight(const CubeBudget& budget, unsigned valueSize, WindowKind kind) {
    // The bytes a window being coded holds per entry beyond its value,
    // measured as the peak a second window in flight adds under
    // --memory-limit 256M (4M entries a window): palette windows their ids
    // and the partitioner's per-distinct-value arrays, about 24; predicted
    // float windows (floats as their integers) 8.6 (the d=1024 sphere, +53
    // MB), taken as 10; predicted integer windows 5.8 (the 512^3 phantom,
    // +41 MB; 26 before the placed walk released the bricks no later brick
    // reads, coding/PlacedWalk.h), taken as 8. A float window without a
    // lattice holds kFloatWindowEntries (1M), the others kValueWindowEntries
    // (4M): counted as 4M, a float window took a quarter of the windows its
    // budget allows (at 64M the d=1024 sphere coded one at a time, 3.9 s;
    // now two, 2.54 s, peak 159 MB).
    const uint64_t overhead = kind == WindowKind::PredictedFloats ? 10 : kind == WindowKind::PredictedIntegers ? 8 : 24;
    const uint64_t entries = kind == WindowKind::PredictedFloats ? attributes::kFloatWindowEntries : attributes::kValueWindowEntries;
    const uint64_t perWindow = entries * (valueSize + overhead);
    return unsigned(std::clamp<uint64_t>(budget.bytes / perWindow, 1, workersOf(budget)));
}

format::EncodedGrid encodeGridByCubes(CubeSource& source, const EncodeOptions& options, const CubeBudget& budget, CubeTeam& team) {
    const std::optional<NormalSource> normals = options.normalBits ? source.normals() : std::nullopt;
    if (options.normalBits && !normals)
        throw Error("--normals: this input gives no normals (a level set or vec3 grid in a .vdb does)");
    format::EncodedGrid out = encodedHeader(source.header(), options);
    const unsigned vs = valueSize(source.header().valueType);
    auto step = [&](const char* name) { if (options.onStep) options.onStep(name); };
    const LayerSummary active = source.summary(Layer::Active);
    out.active.voxels = active.voxels;
    step("reducing the DAG");
    // Values stream from the gather into the value windows, never held
    // whole: lossless ones, and lossy ones quantised on the way (one value
    // at a time, in attribute order) by one process. With several processes
    // each codes the windows of its share and process 0 puts them together
    // (completing the windows that straddle two shares); their lossy values,
    // like colours (clustered over the whole channel), are gathered whole.
    const bool lossy = options.tolerance.mode != attributes::ScalarTolerance::Mode::Exact;
    const bool streamValues = vs > 0 && !isColourGrid(source.header(), options) && (!lossy || team.size() == 1);
    // Gathers the layer into windows (on process 0: all of them).
    auto streamLayer = [&](Layer layer, const LayerPlan& layerPlan, const encoding::CompactDag& dag, uint64_t& entries,
                           attributes::ScalarQuantizer* quantizer) {
        const bool inactiveLayer = layer == Layer::Inactive;
        // A float channel on a rescale lattice is coded as its integers, in
        // windows of integers' size.
        const std::optional<attributes::FloatChannel> floats = floatChannelOf(source.header(), options, inactiveLayer);
        const WindowKind kind = !usesPredictedWindows(source.header(), options, inactiveLayer) ? WindowKind::Palette
                                : floats && !floats->lattice                                 ? WindowKind::PredictedFloats
                                                                                             : WindowKind::PredictedIntegers;
        const unsigned inFlight = valueWindowsInFlight(budget, vs, kind);
        const uint64_t expected = encoding::decodedSize(dag).attributeEntries;
        const bool inactive = layer == Layer::Inactive;
        ValueStream stream;
        stream.quantizer = quantizer;
        auto run = [&](auto& writer) -> attributes::ValueWindowsPayload {
            if (!inactive) writer.trackRange(source.header().valueType);  // the file's Summary section
            const LayerSummary summary = source.summary(layer);
            if constexpr (std::is_same_v<std::decay_t<decltype(writer)>, attributes::ValueWindowWriter>) {
                if (team.size() == 1 && summary.uniform() && summary.uniformValue.size() == vs && !stream.quantizer) {
                    // Every value the same (a level set's inactive voxels):
                    // the layer in attribute order is that value repeated,
                    // so no pass over the cubes gathers it.
                    std::vector<uint8_t> chunk;
                    for (uint64_t done = 0; done < expected;) {
                        const uint64_t n = std::min<uint64_t>(expected - done, attributes::kValueWindowEntries);
                        if (chunk.size() != n * vs) {
                            chunk.clear();
                            for (uint64_t k = 0; k < n; ++k) chunk.insert(chunk.end(), summary.uniformValue.begin(), summary.uniformValue.end());
                        }
                        writer.add(chunk);
                        done += n;
                    }
                } else {
                    gatherLayer(source, layer, layerPlan, dag, vs, budget, team, options.onStepProgress, &stream);
                }
            } else {
                gatherLayer(source, layer, layerPlan, dag, vs, budget, team, options.onStepProgress, &stream);
            }
            if (layer == Layer::Active) step("coding the last value windows");
            if (team.size() == 1) {
                entries = writer.entries();
                return writer.finish();
            }
            // Process 0 puts the shares together one at a time (each into
            // its scratch space as it comes), never holding them all.
            std::optional<std::decay_t<decltype(writer)>> whole;
            if (team.isRoot()) {
                if constexpr (std::is_same_v<std::decay_t<decltype(writer)>, attributes::PredictedWindowWriter>)
                    whole.emplace(vs, inFlight, budget.spillNear, budget.spillInMemory, floatChannelOf(source.header(), options, inactive));
                else
                    whole.emplace(vs, expected, inFlight, budget.spillNear, budget.spillInMemory);
                if (!inactive) whole->trackRange(source.header().valueType);
            }
            team.gatherEach(writer.finishShare().serialize(), [&](std::vector<uint8_t>&& bytes) {
                const attributes::ShareWindows share = attributes::ShareWindows::deserialize(bytes);
                std::vector<uint8_t>().swap(bytes);
                whole->addShare(share);
            });
            if (!team.isRoot()) return {};
            entries = whole->entries();
            if (entries != expected) throw Error("internal error: the processes' values do not add up to the DAG's entries");
            return whole->finish();
        };
        if (usesPredictedWindows(source.header(), options, inactive)) {
            attributes::PredictedWindowWriter writer(vs, inFlight, team.size() == 1 ? budget.spillNear : "", budget.spillInMemory,
                                                     floatChannelOf(source.header(), options, inactive));
            stream.predicted = &writer;
            return run(writer);
        }
        attributes::ValueWindowWriter writer(vs, team.size() == 1 ? expected : 0, inFlight, team.size() == 1 ? budget.spillNear : "",
                                             budget.spillInMemory);
        stream.palette = &writer;
        return run(writer);
    };
    // Each placement candidate's values are gathered and coded (the
    // placement orders them); the smallest file's are kept.
    CodedValues kept, trial;
    auto keep = [&] { kept = std::move(trial); };
    const bool withNormals = normals && normals->cubes;
    if (!active.empty()) {
        const PlanValues codeActive = [&](const encoding::CompactDag& dag, const LayerPlan& layerPlan) -> uint64_t {
            trial = {};
            if (streamValues) {
                step("ordering and coding values");
                attributes::ScalarQuantizer quantizer(source.header().valueType, options.tolerance);
                uint64_t entries = 0;
                trial.windows = streamLayer(Layer::Active, layerPlan, dag, entries, lossy ? &quantizer : nullptr);
                trial.lossy = lossy ? quantizer.finish() : attributes::ToleranceReport{options.tolerance, entries};
            } else {
                step("ordering values");
                trial.attributes = gatherLayer(source, Layer::Active, layerPlan, dag, vs, budget, team, options.onStepProgress);
                step("palette compression");
                if (team.isRoot()) codeActiveValues(dag, trial, source.header(), options);
            }
            if (withNormals) {  // the normals in the same attribute order, from their own source
                const auto normalSource = normals->fromNormalGrid ? attributes::NormalReport::Source::NormalGrid : attributes::NormalReport::Source::Gradient;
                constexpr unsigned kNormalBytes = sizeof(std::array<float, 3>);
                if (team.size() == 1) {  // quantised piece by piece: never held as exact normals
                    attributes::NormalQuantizer quantizer(options.normalBits);
                    ValueStream toCodes;
                    toCodes.normals = &quantizer;
                    gatherLayer(*normals->cubes, Layer::Active, layerPlan, dag, kNormalBytes, budget, team, options.onStepProgress, &toCodes);
                    trial.normals = quantizer.finish(normalSource, normals->oneSided);
                } else {  // process 0 receives them all (the mean error is summed in attribute order)
                    const std::vector<uint8_t> raw = gatherLayer(*normals->cubes, Layer::Active, layerPlan, dag, kNormalBytes, budget, team, options.onStepProgress);
                    std::vector<std::array<float, 3>> exact(raw.size() / kNormalBytes);
                    if (!raw.empty()) std::memcpy(exact.data(), raw.data(), raw.size());
                    if (team.isRoot()) trial.normals = attributes::encodeNormals(exact, options.normalBits, normalSource, normals->oneSided);
                }
            }
            return trial.storedBytes();
        };
        out.active.dag = encodeLayerByCubes(source, Layer::Active, options, budget, vs > 0 || withNormals, &out.stats, team, codeActive, keep);
        storeActiveValues(out, std::move(kept));
    } else {
        step(streamValues ? "coding the last value windows" : "palette compression");
    }
    trial = {};
    const LayerSummary inactive = source.summary(Layer::Inactive);
    out.inactive.voxels = inactive.voxels;
    step("inactive values");
    // A level set's inside, as OpenVDB's signed flood fill makes it from
    // exact active values: the reader makes it again (InactiveSignedFill.h).
    out.inactiveSignedFill = !inactive.empty() && options.tolerance.mode == attributes::ScalarTolerance::Mode::Exact && source.inactiveIsSignedFill();
    if (!inactive.empty() && !out.inactiveSignedFill) {
        const PlanValues codeInactive = [&](const encoding::CompactDag& dag, const LayerPlan& layerPlan) -> uint64_t {
            trial = {};
            if (vs > 0) {  // streamed, as the active values above
                uint64_t entries = 0;
                trial.windows = streamLayer(Layer::Inactive, layerPlan, dag, entries, nullptr);
            } else {
                trial.attributes = gatherLayer(source, Layer::Inactive, layerPlan, dag, vs, budget, team, options.onStepProgress);
                if (team.isRoot()) codeInactiveValues(dag, trial, source.header(), options);
            }
            return trial.storedBytes();
        };
        out.inactive.dag = encodeLayerByCubes(source, Layer::Inactive, options, budget, vs > 0, nullptr, team, codeInactive, keep);
        storeInactiveValues(out, std::move(kept));
    }
    if (team.isRoot()) out.summary = format::summaryToStore(out);  // the file's Summary section
    return out;
}

format::SsvdagScene encodeSourcesByCubes(std::vector<std::unique_ptr<CubeSource>> grids, std::vector<uint8_t> fileMetadata,
                                         const EncodeOptions& options, const CubeBudget& budget, const GridProgress& onGrid, CubeTeam& team) {
    format::SsvdagScene scene;
    scene.fileMetadata = std::move(fileMetadata);
    for (size_t g = 0; g < grids.size(); ++g) {
        if (onGrid) onGrid(g, grids.size());
        scene.grids.push_back(encodeGridByCubes(*grids[g], options, budget, team));
        grids[g].reset();
        std::vector<uint8_t>().swap(scene.grids.back().active.attributes);
        std::vector<uint8_t>().swap(scene.grids.back().inactive.attributes);
    }
    return scene;
}

} // namespace vdbdag::pipeline
