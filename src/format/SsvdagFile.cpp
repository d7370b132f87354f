// Mapping between SsvdagScene and container sections. Section payloads:
//   FileInfo      u32 grid count, string writer
//   FileMetadata  opaque bytes (vdb_bridge: the .vdb file's MetaMap); absent
//                 when the file has no metadata
//   GridInfo      string name, string class, u8 value type, u8 symmetry,
//                 f64[16] index-to-world, u64 active voxels,
//                 string background (raw value bytes), u64 inactive voxels
//   VdbDescriptor opaque bytes (vdb_bridge)
//   DagLevels     i64[3] origin, u8 log2Size, u8 root reflection,
//                 u32 n, u64[n] level starts, u8[n] attribute-offset words
//                 (| 0x80: kept at rest as 0, CompactDag.h kOffsetsAtRest),
//                 u64 inner words, u64 leaves
//   DagInner      u16[inner words]     (absent for an empty grid)
//   DagLeaves     u64[leaves]          (absent for an empty grid)
//   DagStats      u32 n, u8 hasSvdag, then n x (u64 svo, u64 svdag, u64 stored)
//   ValueWindows  the active values in attribute order, palette-coded and
//                 zstd'd in fixed windows (src/attributes/ValueWindows.h);
//                 what the encoder writes
//   Values        the same as one palette channel (serializePalette in
//                 src/attributes/PaletteChannel.cpp), still read
//   PredictedWindows  instead, for int32/int64 channels: brick-aligned
//                 windows, each palette-coded or brick-MED predicted
//                 (src/attributes/PredictedWindows.h); what the encoder
//                 writes for integers
//   PredictedValues  the same values as brick-MED residuals in one channel
//                 (src/attributes/PredictedChannel.h), still read; the
//                 reader decodes them along the DAG and rebuilds the
//                 palette channel
//   Inactive*     the same for the inactive layer (absent if empty)
//   ValueErrors   lossy only: u8 mode, f64 bound, u64 entries, changed, kept
//                 exact, f64 max abs, mean abs, RMS, max relative error
//   ColourErrors  --colour-bits only: u8 bits, u64 entries, distinct before,
//                 distinct after, changed, f64[3] mean abs error (R, G, B in
//                 0..255 units), f64[3] max abs error, f64 mean and max ΔE94
//   Normals       --normals only: see src/attributes/NormalChannel.cpp
// Strings are u32 length + bytes. Everything little-endian (ByteIO.h).
#include "src/format/SsvdagFile.h"

#include <limits>
#include <algorithm>
#include <map>
#include <set>
#include <optional>

#include "src/attributes/PredictedChannel.h"
#include "src/attributes/PredictedWindows.h"
#include "src/attributes/ValueWindows.h"
#include "src/format/ByteIO.h"
#include "src/format/DagBounds.h"
#include "src/format/FrameSequence.h"
#include "src/format/InactiveSignedFill.h"
#include "src/format/ValueReference.h"
#include "src/encoding/AttributeLayout.h"
#include "src/util/Error.h"

namespace vdbdag::format {
namespace {

constexpr const char* kWriter = "vdbdag 0.1";

template <typename T>
std::vector<uint8_t> rawBytes(const std::vector<T>& values) {
    const auto* p = reinterpret_cast<const uint8_t*>(values.data());
    return std::vector<uint8_t>(p, p + values.size() * sizeof(T));
}

template <typename T>
std::vector<T> fromRawBytes(const std::vector<uint8_t>& bytes, uint64_t expectedCount, const std::string& what) {
    if (bytes.size() % sizeof(T) != 0 || bytes.size() / sizeof(T) != expectedCount)
        throw Error(what + ": holds " + std::to_string(bytes.size()) + " bytes, expected " + std::to_string(expectedCount * sizeof(T)));
    std::vector<T> values(expectedCount);
    if (!bytes.empty()) std::memcpy(values.data(), bytes.data(), bytes.size());
    return values;
}

struct LayerKinds {
    SectionKind levels, inner, leaves, values, predicted, windows, predictedWindows;
};
constexpr LayerKinds kActive{SectionKind::DagLevels,       SectionKind::DagInner,     SectionKind::DagLeaves,       SectionKind::Values,
                             SectionKind::PredictedValues, SectionKind::ValueWindows, SectionKind::PredictedWindows};
constexpr LayerKinds kInactive{SectionKind::InactiveLevels,          SectionKind::InactiveInner,        SectionKind::InactiveLeaves,
                               SectionKind::InactiveValues,          SectionKind::InactivePredictedValues, SectionKind::InactiveValueWindows,
                               SectionKind::InactivePredictedWindows};

} // namespace

std::vector<uint8_t> serializeDagLevels(const encoding::CompactDag& dag) {
    ByteWriter levels;
    for (int64_t o : dag.origin) levels.put<int64_t>(o);
    levels.put<uint8_t>(dag.log2Size);
    levels.put<uint8_t>(dag.rootReflection);
    levels.put<uint32_t>(uint32_t(dag.levelStart.size()));
    for (uint64_t s : dag.levelStart) levels.put<uint64_t>(s);
    for (uint8_t w : encoding::offsetWordsAtRest(dag)) levels.put<uint8_t>(w);  // offsets at rest (FORMAT.md 6.1)
    levels.put<uint64_t>(dag.inner.size());
    levels.put<uint64_t>(dag.leaves.size());
    return levels.take();
}

// Summary (docs/FORMAT.md 10.1): u8 flags (1: an index box, 2: a value
// range), [i64 min[3], i64 max[3]], u64 solid nodes, u64 active entries,
// u64 inactive entries, [min, max: the value's bytes each].
std::vector<uint8_t> serializeSummary(const StoredSummary& s, unsigned valueSize) {
    const bool range = valueSize && !s.activeRange.empty();
    if (range && (s.activeRange.min.size() != valueSize || s.activeRange.max.size() != valueSize))
        throw Error("internal error: a value range of the wrong size");
    ByteWriter w;
    w.put<uint8_t>(uint8_t((s.indexBox ? 1 : 0) | (range ? 2 : 0)));
    if (s.indexBox) {
        for (int64_t v : s.indexBox->min) w.put<int64_t>(v);
        for (int64_t v : s.indexBox->max) w.put<int64_t>(v);
    }
    w.put<uint64_t>(s.solidNodes);
    w.put<uint64_t>(s.activeEntries);
    w.put<uint64_t>(s.inactiveEntries);
    if (range) {
        w.putBytes(s.activeRange.min);
        w.putBytes(s.activeRange.max);
    }
    return w.take();
}

StoredSummary parseSummary(std::span<const uint8_t> bytes, unsigned valueSize, const std::string& what) {
    ByteReader r(bytes, what);
    StoredSummary s;
    const uint8_t flags = r.get<uint8_t>();
    if (flags > 3) r.fail("unknown flags " + std::to_string(flags));
    if ((flags & 2) && !valueSize) r.fail("a value range for a grid without values");
    if (flags & 1) {
        IndexBox box;
        for (int64_t& v : box.min) v = r.get<int64_t>();
        for (int64_t& v : box.max) v = r.get<int64_t>();
        for (int a = 0; a < 3; ++a)
            if (box.min[size_t(a)] > box.max[size_t(a)]) r.fail("an index box whose minimum lies past its maximum");
        s.indexBox = box;
    }
    s.solidNodes = r.get<uint64_t>();
    s.activeEntries = r.get<uint64_t>();
    s.inactiveEntries = r.get<uint64_t>();
    if (flags & 2) {
        s.activeRange.min = r.getArray<uint8_t>(valueSize);
        s.activeRange.max = r.getArray<uint8_t>(valueSize);
    }
    r.expectEnd();
    return s;
}

std::vector<uint8_t> serializeDagStats(const DagStats& st) {
    ByteWriter stats;
    stats.put<uint32_t>(uint32_t(st.svoNodes.size()));
    stats.put<uint8_t>(st.hasSvdag ? 1 : 0);
    for (size_t i = 0; i < st.svoNodes.size(); ++i) {
        stats.put<uint64_t>(st.svoNodes[i]);
        stats.put<uint64_t>(i < st.svdagNodes.size() ? st.svdagNodes[i] : 0);
        stats.put<uint64_t>(i < st.storedNodes.size() ? st.storedNodes[i] : 0);
    }
    return stats.take();
}

namespace {

// `take`: move (or release) the layer's payloads out of the scene instead of copying them.
template <typename T>
std::vector<T> takeOrCopy(std::vector<T>& v, bool take) {
    if (!take) return v;
    std::vector<T> out;
    out.swap(v);
    return out;
}
template <typename T>
void releaseIf(std::vector<T>& v, bool take) {
    if (take) std::vector<T>().swap(v);
}

void putLayer(std::vector<Section>& sections, uint32_t g, const LayerKinds& kinds, EncodedLayer& layer, unsigned valueSize, bool take) {
    encoding::CompactDag& dag = layer.dag;
    attributes::ValueWindowsPayload& windows = layer.valueWindows;
    std::vector<uint8_t>& predicted = layer.predictedValues;
    sections.push_back({kinds.levels, g, serializeDagLevels(dag)});
    if (!dag.empty()) {
        const SectionKind windowKind = windows.predicted ? kinds.predictedWindows : kinds.windows;
        sections.push_back({kinds.inner, g, rawBytes(encoding::innerWordsAtRest(dag))});
        releaseIf(dag.inner, take);
        if (!dag.leaves.empty()) sections.push_back({kinds.leaves, g, rawBytes(dag.leaves)});
        releaseIf(dag.leaves, take);
        if (valueSize && windows.referenceDistance && !predicted.empty()) throw Error("internal error: a reference for values not in windows");
        if (valueSize && windows.referenceDistance) {  // FORMAT.md 8.6
            if (kinds.predictedWindows != SectionKind::PredictedWindows || !windows.predicted)
                throw Error("internal error: a series' reference for an inactive layer or palette windows");
            ByteWriter w;
            w.put<uint32_t>(windows.referenceDistance);
            sections.push_back({SectionKind::ValueReference, g, w.take()});
        }
        if (valueSize && !predicted.empty()) sections.push_back({kinds.predicted, g, takeOrCopy(predicted, take)});
        else if (valueSize && windows.file) sections.push_back({windowKind, g, {}, take ? std::move(windows.file) : windows.file});
        else if (valueSize && !windows.empty()) sections.push_back({windowKind, g, takeOrCopy(windows.bytes, take)});
        else if (valueSize) sections.push_back({kinds.values, g, attributes::serializePalette(layer.values)});
    }
}

} // namespace


namespace {

// With `take`, the scene's DAGs, value payloads and descriptors move into the
// sections (the headers and reports stay); without it the scene is only read.
std::vector<Section> toSections(SsvdagScene& scene, bool take) {
    std::vector<Section> sections;
    {
        ByteWriter w;
        w.put<uint32_t>(uint32_t(scene.grids.size()));
        w.putString(kWriter);
        sections.push_back({SectionKind::FileInfo, 0, w.take()});
    }
    if (!scene.fileMetadata.empty()) sections.push_back({SectionKind::FileMetadata, 0, scene.fileMetadata});
    std::vector<FrameEntry> frames;
    for (const SceneFrame& f : scene.frames) frames.push_back({f.number, f.gridCount});
    if (!frames.empty()) sections.push_back({SectionKind::Frames, 0, serializeFrames(frames)});
    size_t nextFrame = 0;
    for (uint32_t g = 0; g < scene.grids.size(); ++g) {
        if (nextFrame < scene.frames.size() && scene.frames[nextFrame].firstGrid == g) {
            SceneFrame& f = scene.frames[nextFrame++];
            if (!f.metadata.empty()) sections.push_back({SectionKind::FrameMetadata, g, takeOrCopy(f.metadata, take)});
        }
        EncodedGrid& grid = scene.grids[g];
        ByteWriter info;
        info.putString(grid.record.name);
        info.putString(grid.record.gridClass);
        info.put<uint8_t>(uint8_t(grid.record.valueType));
        info.put<uint8_t>(grid.symmetry ? 1 : 0);
        for (double v : grid.record.indexToWorld) info.put<double>(v);
        info.put<uint64_t>(grid.active.voxels);
        info.putString(std::string(grid.record.background.begin(), grid.record.background.end()));
        info.put<uint64_t>(grid.inactive.voxels);
        sections.push_back({SectionKind::GridInfo, g, info.take()});
        sections.push_back({SectionKind::VdbDescriptor, g, takeOrCopy(grid.record.vdbDescriptor, take)});

        const unsigned vs = valueSize(grid.record.valueType);
        putLayer(sections, g, kActive, grid.active, vs, take);
        if (grid.inactiveSignedFill) sections.push_back({SectionKind::InactiveSignedFill, g, {0}});  // u8 0: the fill of SignedFill.h
        else if (!grid.inactive.dag.empty()) putLayer(sections, g, kInactive, grid.inactive, vs, take);
        if (grid.lossy.tolerance.mode != attributes::ScalarTolerance::Mode::Exact) {
            ByteWriter e;
            const auto& l = grid.lossy;
            e.put<uint8_t>(uint8_t(l.tolerance.mode));
            e.put<double>(l.tolerance.bound);
            for (uint64_t v : {l.entries, l.changed, l.keptExact}) e.put<uint64_t>(v);
            for (double v : {l.maxAbsError, l.meanAbsError, l.rmsError, l.maxRelError}) e.put<double>(v);
            sections.push_back({SectionKind::ValueErrors, g, e.take()});
        }
        if (grid.colour) {
            ByteWriter e;
            const auto& c = *grid.colour;
            e.put<uint8_t>(uint8_t(c.bits));
            for (uint64_t v : {c.entries, c.distinctBefore, c.distinctAfter, c.changed}) e.put<uint64_t>(v);
            for (double v : c.meanAbsError) e.put<double>(v);
            for (double v : c.maxAbsError) e.put<double>(v);
            e.put<double>(c.meanDeltaE94);
            e.put<double>(c.maxDeltaE94);
            sections.push_back({SectionKind::ColourErrors, g, e.take()});
        }
        if (grid.normals) sections.push_back({SectionKind::Normals, g, attributes::serializeNormals(*grid.normals)});
        sections.push_back({SectionKind::DagStats, g, serializeDagStats(grid.stats)});
        if (grid.summary) sections.push_back({SectionKind::Summary, g, serializeSummary(*grid.summary, vs)});
    }
    return sections;
}

} // namespace

std::vector<Section> sceneToSections(const SsvdagScene& scene) { return toSections(const_cast<SsvdagScene&>(scene), false); }  // read only

uint64_t writeSceneReleasing(SsvdagScene& scene, std::ostream& out, const ContainerOptions& options) {
    return writeContainerTo(toSections(scene, true), out, options);
}

SsvdagScene sectionsToScene(std::vector<Section> sections, const std::string& sourceName) {
    return sectionsToScene(std::move(sections), sourceName, ReadOptions{});
}

namespace {

// A sequence file's SameAs sections (4.3) replaced by copies of the
// sections they name, weighed against the memory limit before any is made.
void resolveSameAs(std::vector<Section>& sections, const std::string& sourceName, const ReadOptions& options) {
    std::vector<std::pair<uint32_t, std::vector<SameAsEntry>>> wanted;
    for (const Section& s : sections)
        if (s.kind == SectionKind::SameAs) wanted.push_back({s.grid, parseSameAs(s.data, s.grid, sourceName + ": SameAs of grid " + std::to_string(s.grid))});
    if (wanted.empty()) return;
    std::map<std::pair<uint32_t, SectionKind>, size_t> real;
    for (size_t i = 0; i < sections.size(); ++i)
        if (sections[i].kind != SectionKind::SameAs) real.emplace(std::make_pair(sections[i].grid, sections[i].kind), i);
    uint64_t copies = 0;
    std::vector<std::pair<size_t, Section>> made;  // (source, the copy's kind and grid)
    for (const auto& [grid, entries] : wanted)
        for (const SameAsEntry& e : entries) {
            const auto it = real.find({e.grid, e.kind});
            if (it == real.end()) {
                // Reading one frame, only its own grids need their sections.
                if (options.frame || options.grid || options.headersOnly) continue;
                throw Error(sourceName + ": grid " + std::to_string(grid) + " takes its " + sectionKindName(e.kind) + " from grid " +
                            std::to_string(e.grid) + ", which has none");
            }
            if (real.contains({grid, e.kind}))
                throw Error(sourceName + ": grid " + std::to_string(grid) + " has its own " + sectionKindName(e.kind) + " and takes one from grid " +
                            std::to_string(e.grid));
            copies = saturatingAdd(copies, sections[it->second].data.size());
            made.push_back({it->second, Section{e.kind, grid, {}}});
        }
    checkMemory(options.limits, copies, sourceName, "the sections its unchanged grids share,");
    for (auto& [source, copy] : made) copy.data = sections[source].data;
    sections.erase(std::remove_if(sections.begin(), sections.end(), [](const Section& s) { return s.kind == SectionKind::SameAs; }), sections.end());
    for (auto& [source, copy] : made) sections.push_back(std::move(copy));
}

} // namespace

SsvdagScene sectionsToScene(std::vector<Section> sections, const std::string& sourceName, const ReadOptions& options) {
    resolveSameAs(sections, sourceName, options);
    const Section* fileInfo = nullptr;
    const Section* framesSection = nullptr;
    Section* fileMetadata = nullptr;
    std::map<uint32_t, Section*> frameMetadata;  // by the frame's first grid
    std::map<std::pair<uint32_t, SectionKind>, Section*> byGrid;
    for (Section& s : sections) {
        if (s.kind == SectionKind::FileInfo || s.kind == SectionKind::Frames) {
            const Section*& slot = s.kind == SectionKind::FileInfo ? fileInfo : framesSection;
            if (slot) throw Error(sourceName + ": two " + sectionKindName(s.kind) + " sections");
            if (s.grid != 0) throw Error(sourceName + ": a " + sectionKindName(s.kind) + " section belongs to the file, not to grid " + std::to_string(s.grid));
            slot = &s;
            continue;
        }
        if (s.kind == SectionKind::FrameMetadata) {
            if (!frameMetadata.emplace(s.grid, &s).second) throw Error(sourceName + ": two FrameMetadata sections for grid " + std::to_string(s.grid));
            continue;
        }
        if (s.kind == SectionKind::FileMetadata) {
            if (fileMetadata) throw Error(sourceName + ": two FileMetadata sections");
            if (s.grid != 0) throw Error(sourceName + ": a FileMetadata section belongs to the file, not to grid " + std::to_string(s.grid));
            fileMetadata = &s;
            continue;
        }
        if (!byGrid.emplace(std::make_pair(s.grid, s.kind), &s).second)
            throw Error(sourceName + ": duplicate section '" + sectionKindName(s.kind) + "' for grid " + std::to_string(s.grid));
    }
    if (!fileInfo) throw Error(sourceName + ": missing FileInfo section");
    ByteReader fr(fileInfo->data, sourceName + ": FileInfo");
    const uint32_t gridCount = fr.get<uint32_t>();
    fr.getString();
    // The frames, and the grids [first, end) this read builds: all of
    // them, or one frame's (ReadOptions::frame).
    std::vector<FrameEntry> frames;
    if (framesSection) frames = parseFrames(framesSection->data, gridCount, sourceName + ": Frames");
    if (framesSection && fileMetadata) throw Error(sourceName + ": a sequence file keeps each frame's metadata in FrameMetadata, not FileMetadata");
    if (!framesSection && !frameMetadata.empty()) throw Error(sourceName + ": FrameMetadata in a file without frames");
    if (options.grid && *options.grid >= gridCount)
        throw Error(sourceName + ": has " + std::to_string(gridCount) + " grid(s); grid " + std::to_string(*options.grid) + " asked for");
    const GridRange range = options.frame ? frameGrids(frames, gridCount, *options.frame, sourceName)
                            : options.grid ? GridRange{*options.grid, *options.grid + 1}
                                           : GridRange{0, gridCount};
    uint32_t first = range.first;
    const uint32_t end = range.end;
    if (end - first > sections.size()) throw Error(sourceName + ": FileInfo claims " + std::to_string(gridCount) + " grids, more than its sections can hold");

    auto find = [&](uint32_t g, SectionKind kind, bool required) -> Section* {
        auto it = byGrid.find({g, kind});
        if (it == byGrid.end()) {
            if (required) throw Error(sourceName + ": grid " + std::to_string(g) + " has no '" + sectionKindName(kind) + "' section");
            return nullptr;
        }
        return it->second;
    };

    // One grid asked for whose values take an earlier grid's as their
    // reference (FORMAT.md 8.6): the grids of its chain are read too, back
    // to its key grid, and dropped once it is read.
    if (options.grid && !options.referencesByCaller) {
        first = referenceChainStart(first, [&](uint32_t g) -> const Section* { return find(g, SectionKind::ValueReference, false); }, sourceName);
        if (end - first > sections.size()) throw Error(sourceName + ": grid " + std::to_string(end - 1) + "'s reference chain claims more grids than its sections can hold");
    }

    SsvdagScene scene;
    if (fileMetadata) scene.fileMetadata = std::move(fileMetadata->data);
    {
        uint32_t firstGrid = 0;
        for (const FrameEntry& f : frames) {
            std::vector<uint8_t> metadata;
            if (auto meta = frameMetadata.find(firstGrid); meta != frameMetadata.end()) {
                metadata = std::move(meta->second->data);
                frameMetadata.erase(meta);
            }
            if (!options.frame) scene.frames.push_back({f.number, firstGrid, f.gridCount, std::move(metadata)});
            else if (firstGrid == first) scene.fileMetadata = std::move(metadata);
            firstGrid += f.gridCount;
        }
        if (!frameMetadata.empty())
            throw Error(sourceName + ": FrameMetadata for grid " + std::to_string(frameMetadata.begin()->first) + ", which does not begin a frame");
    }
    uint64_t expanded = 0;  // bytes the sections and what is decoded from them take
    ReferenceReads references;  // grids other grids take their values' reference from (FORMAT.md 8.6)
    references.expanded = &expanded;
    references.limits = &options.limits;
    for (const Section& s : sections) expanded = saturatingAdd(expanded, s.data.size());
    scene.grids.resize(end - first);
    for (uint32_t g = first; g < end; ++g) {
        EncodedGrid& grid = scene.grids[g - first];
        const std::string what = sourceName + ": grid " + std::to_string(g);
        {
            ByteReader r(find(g, SectionKind::GridInfo, true)->data, what + " GridInfo");
            grid.record.name = r.getString();
            grid.record.gridClass = r.getString();
            const uint8_t type = r.get<uint8_t>();
            if (type > uint8_t(ValueType::Vec3I)) r.fail("unknown value type " + std::to_string(type));
            grid.record.valueType = ValueType(type);
            grid.symmetry = r.get<uint8_t>() != 0;
            for (double& v : grid.record.indexToWorld) v = r.get<double>();
            grid.active.voxels = r.get<uint64_t>();
            const std::string background = r.getString(64);
            grid.record.background.assign(background.begin(), background.end());
            grid.inactive.voxels = r.get<uint64_t>();
            r.expectEnd();
            if (grid.record.background.size() != valueSize(grid.record.valueType)) r.fail("background value has the wrong size");
        }
        grid.record.vdbDescriptor = std::move(find(g, SectionKind::VdbDescriptor, true)->data);
        const unsigned vs = valueSize(grid.record.valueType);
        // A layer's DAG first (both layers' before any value), so what the
        // values will take is weighed before any is decoded.
        auto readLayerDag = [&](const LayerKinds& kinds, EncodedLayer& into, const std::string& layer) -> encoding::DecodedSize {
            encoding::CompactDag& dag = into.dag;
            const uint64_t expectedVoxels = into.voxels;
            uint64_t innerWords = 0, leafCount = 0;
            {
                ByteReader r(find(g, kinds.levels, true)->data, what + " " + layer + " levels");
                for (int64_t& o : dag.origin) o = r.get<int64_t>();
                dag.log2Size = r.get<uint8_t>();
                dag.rootReflection = r.get<uint8_t>();
                const uint32_t n = r.get<uint32_t>();
                dag.levelStart = r.getArray<uint64_t>(n);
                dag.offsetWords = r.getArray<uint8_t>(n);
                innerWords = r.get<uint64_t>();
                leafCount = r.get<uint64_t>();
                r.expectEnd();
            }
            if (options.headersOnly) {
                for (uint8_t& w : dag.offsetWords) w &= uint8_t(~encoding::kOffsetsAtRest);
                return encoding::DecodedSize{};
            }
            Section* inner = find(g, kinds.inner, dag.log2Size != 0);
            Section* leaves = find(g, kinds.leaves, false);
            if (inner) dag.inner = fromRawBytes<uint16_t>(inner->data, innerWords, what + " " + layer + " inner nodes");
            else if (innerWords) throw Error(what + ": " + layer + " levels claim inner words but there is no inner section");
            if (leaves) dag.leaves = fromRawBytes<uint64_t>(leaves->data, leafCount, what + " " + layer + " leaves");
            else if (leafCount) throw Error(what + ": " + layer + " levels claim leaves but there is no leaf section");
            for (uint64_t s : dag.levelStart)
                if (s > dag.inner.size()) throw Error(what + ": " + layer + " level start " + std::to_string(s) + " beyond the inner array");
            const encoding::DecodedSize size = encoding::validateAndRestoreOffsets(dag, what + " " + layer);
            // Every voxel must have an OpenVDB (int32) index: refused here,
            // naming the file, rather than when a decode reaches the voxel.
            if (const std::optional<IndexBox> box = dagBounds(dag))
                for (int a = 0; a < 3; ++a)
                    if (box->min[size_t(a)] < std::numeric_limits<int32_t>::min() || box->max[size_t(a)] > std::numeric_limits<int32_t>::max())
                        throw Error(what + ": the " + layer + " DAG reaches voxel index " +
                                    std::to_string(box->min[size_t(a)] < std::numeric_limits<int32_t>::min() ? box->min[size_t(a)] : box->max[size_t(a)]) +
                                    " on axis " + "xyz"[a] + ", outside OpenVDB's int32 index range; the file is corrupted");
            if (size.activeVoxels != expectedVoxels)
                throw Error(what + ": the " + layer + " DAG holds " + std::to_string(size.activeVoxels) + " voxels but the header says " +
                            std::to_string(expectedVoxels) + "; the file is corrupted");
            // What this layer will take at least, before any value is
            // decoded: its entries (each voxel of a brick, each tile once)
            // as decoded values, unless they stay in windows, and as the
            // command's own copies.
            checkVoxels(options.limits, size.attributeEntries, what + " " + layer + " layer");
            // Values of the layout before windows (one Values or
            // PredictedValues section) are decoded whole even when windows
            // are kept: no reader leaves them in the file.
            const bool wholeValues = find(g, kinds.values, false) || find(g, kinds.predicted, false);
            const bool decodesValues = vs && !dag.empty() && (!options.keepValueWindows || wholeValues);
            expanded = saturatingAdd(expanded, saturatingMul(size.attributeEntries, decodesValues ? uint64_t(vs) : 0));
            expanded = saturatingAdd(expanded, saturatingMul(size.attributeEntries, uint64_t(std::max(vs, 1u)) * options.limits.valueCopies));
            checkMemory(options.limits, expanded, what, "its sections and decoded values");
            return size;
        };
        auto readLayerValues = [&](const LayerKinds& kinds, EncodedLayer& into, const encoding::DecodedSize& size, const std::string& layer) {
            const encoding::CompactDag& dag = into.dag;
            std::vector<uint8_t>& attributes = into.attributes;
            attributes::PaletteChannel& channel = into.values;
            std::vector<uint8_t>& predicted = into.predictedValues;
            attributes::ValueWindowsPayload& windows = into.valueWindows;
            Section* predictedSection = find(g, kinds.predicted, false);
            Section* windowSection = find(g, kinds.windows, false);
            Section* paletteSection = find(g, kinds.values, false);
            Section* predictedWindowSection = find(g, kinds.predictedWindows, false);
            if (int(predictedSection != nullptr) + int(windowSection != nullptr) + int(paletteSection != nullptr) + int(predictedWindowSection != nullptr) > 1)
                throw Error(what + ": the " + layer + " values are stored twice (more than one of Values, ValueWindows, PredictedValues, PredictedWindows)");
            if (kinds.predictedWindows == SectionKind::PredictedWindows && find(g, SectionKind::ValueReference, false) && !predictedWindowSection)
                throw Error(what + ": a ValueReference section for " + layer + " values not in predicted windows");
            if ((predictedSection || windowSection || predictedWindowSection) && (!vs || dag.empty()))
                throw Error(what + ": unexpected " + layer + " values section for a grid without values");
            if (predictedSection || predictedWindowSection) {
                // Integers; float32 and vec3s too in windows (codings 5, 8, 9).
                const ValueType type = grid.record.valueType;
                if (type != ValueType::Int32 && type != ValueType::Int64 && !(predictedWindowSection && (type == ValueType::Float || type == ValueType::Vec3S)))
                    throw Error(what + ": predicted values for a " + valueTypeName(type) + " grid");
                if (predictedSection) {
                    predicted = std::move(predictedSection->data);
                    attributes = attributes::decodePredicted(predicted, vs, encoding::attributeLayout(dag), what + " " + layer + " values");
                }
                // A series' reference (FORMAT.md 8.6): an earlier grid of this read, whose windows this layer's may read.
                attributes::ReferenceWindow referenceWindow;
                Section* ref = kinds.predictedWindows == SectionKind::PredictedWindows ? find(g, SectionKind::ValueReference, false) : nullptr;
                if (ref && options.grid && options.referencesByCaller) {
                    if (!options.keepValueWindows) throw Error("internal error: a grid's reference left to a caller that decodes its values now");
                    ref = nullptr;  // the caller's (its referenceDistance is set below)
                }
                if (ref) {
                    if (!predictedWindowSection) throw Error(what + ": a ValueReference section for values not in predicted windows");
                    referenceWindow = readValueReference(*ref, g, first, scene, into, predictedWindowSection->data, vs, !options.keepValueWindows, references,
                                                         what, sourceName);
                }
                if (predictedSection) {
                    // decoded above
                } else if (options.keepValueWindows) {
                    windows.bytes = std::move(predictedWindowSection->data);
                    windows.predicted = true;
                    attributes::readPredictedWindowDirectory(windows.bytes, vs, encoding::attributeLayout(dag), what + " " + layer + " predicted windows");
                    return;
                } else {
                    const std::vector<uint64_t> layoutHere = encoding::attributeLayout(dag);
                    const std::vector<coding::BrickPlace> placesHere = encoding::attributePlaces(dag, vs);
                    if (!referenceWindow) referenceWindow = attributes::referenceWindows(windows.reference, layoutHere, placesHere);
                    attributes = attributes::decodePredictedWindows(predictedWindowSection->data, vs, layoutHere, what + " " + layer + " predicted windows",
                                                                    placesHere, options.parallel, referenceWindow);
                    windows.bytes = std::move(predictedWindowSection->data);  // kept as it is: a rewrite stores it again
                    windows.predicted = true;
                }
                if (attributes.size() != size.attributeEntries * vs)
                    throw Error(what + ": " + layer + " predicted values hold " + std::to_string(attributes.size() / vs) + " entries, expected " +
                                std::to_string(size.attributeEntries));
            } else if (vs && !dag.empty() && windowSection && options.keepValueWindows) {
                windows.bytes = std::move(windowSection->data);
                const attributes::WindowDirectory d = attributes::readValueWindowDirectory(windows.bytes, what + " " + layer + " value windows");
                if (d.valueSize != vs || d.entries != size.attributeEntries)
                    throw Error(what + ": " + layer + " value windows hold " + std::to_string(d.entries) + " entries of " + std::to_string(d.valueSize) +
                                " bytes, expected " + std::to_string(size.attributeEntries) + " of " + std::to_string(vs));
            } else if (vs && !dag.empty()) {
                if (windowSection) channel = attributes::decodeValueWindows(windowSection->data, what + " " + layer + " value windows");
                else channel = attributes::deserializePalette(find(g, kinds.values, true)->data, what + " " + layer + " values");
                if (channel.valueSize != vs || channel.entryCount != size.attributeEntries)
                    throw Error(what + ": " + layer + " values hold " + std::to_string(channel.entryCount) + " entries of " +
                                std::to_string(channel.valueSize) + " bytes, expected " + std::to_string(size.attributeEntries) + " of " + std::to_string(vs));
                attributes = channel.decodeAll();
            }
        };
        const encoding::DecodedSize activeSize = readLayerDag(kActive, grid.active, "active");
        if (Section* ref = find(g, SectionKind::ValueReference, false)) grid.active.valueWindows.referenceDistance = parseValueReference(*ref, sourceName);
        if (Section* fill = find(g, SectionKind::InactiveSignedFill, false)) {
            ByteReader r(fill->data, what + " InactiveSignedFill");
            if (r.get<uint8_t>() != 0) r.fail("an unknown fill");
            r.expectEnd();
            for (SectionKind k : {kInactive.levels, kInactive.inner, kInactive.leaves, kInactive.values, kInactive.predicted, kInactive.windows, kInactive.predictedWindows})
                if (find(g, k, false)) throw Error(what + ": corrupt (an inactive layer beside its signed fill)");
            grid.inactiveSignedFill = true;
        }
        const bool inactiveLayer = !grid.inactiveSignedFill && (grid.inactive.voxels || find(g, kInactive.levels, false));
        const encoding::DecodedSize inactiveSize = inactiveLayer ? readLayerDag(kInactive, grid.inactive, "inactive") : encoding::DecodedSize{};
        if (!options.headersOnly) readLayerValues(kActive, grid.active, activeSize, "active");
        if (inactiveLayer && !options.headersOnly) readLayerValues(kInactive, grid.inactive, inactiveSize, "inactive");
        if (grid.inactiveSignedFill && !options.headersOnly && options.signedFillLayer) restoreSignedFill(grid, options.parallel, what);
        if (Section* e = find(g, SectionKind::ValueErrors, false)) {
            ByteReader r(e->data, what + " ValueErrors");
            auto& l = grid.lossy;
            const uint8_t mode = r.get<uint8_t>();
            if (mode > 2) r.fail("unknown tolerance mode");
            l.tolerance.mode = attributes::ScalarTolerance::Mode(mode);
            l.tolerance.bound = r.get<double>();
            l.entries = r.get<uint64_t>();
            l.changed = r.get<uint64_t>();
            l.keptExact = r.get<uint64_t>();
            l.maxAbsError = r.get<double>();
            l.meanAbsError = r.get<double>();
            l.rmsError = r.get<double>();
            l.maxRelError = r.get<double>();
            r.expectEnd();
        }
        if (Section* e = find(g, SectionKind::ColourErrors, false)) {
            ByteReader r(e->data, what + " ColourErrors");
            attributes::ColourReport c;
            c.bits = r.get<uint8_t>();
            if (c.bits < 1 || c.bits > 16) r.fail("colour bits " + std::to_string(c.bits) + " outside 1..16");
            if (!attributes::isVec3Type(grid.record.valueType)) r.fail("colour errors for a grid that is not a vec3 grid");
            c.entries = r.get<uint64_t>();
            c.distinctBefore = r.get<uint64_t>();
            c.distinctAfter = r.get<uint64_t>();
            c.changed = r.get<uint64_t>();
            for (double& v : c.meanAbsError) v = r.get<double>();
            for (double& v : c.maxAbsError) v = r.get<double>();
            c.meanDeltaE94 = r.get<double>();
            c.maxDeltaE94 = r.get<double>();
            r.expectEnd();
            if (c.distinctAfter > (uint64_t(1) << c.bits) && c.distinctAfter != c.distinctBefore) r.fail("more colours than the bits allow");
            grid.colour = c;
        }
        if (Section* n = options.headersOnly ? nullptr : find(g, SectionKind::Normals, false)) {
            if (grid.active.dag.empty()) throw Error(what + ": normals for an empty grid");
            grid.normals = attributes::deserializeNormals(n->data, encoding::decodedSize(grid.active.dag).attributeEntries, what + " Normals");
        }
        if (Section* st = find(g, SectionKind::DagStats, false)) {
            ByteReader r(st->data, what + " DagStats");
            const uint32_t n = r.get<uint32_t>();
            if (n > 64) r.fail("implausible level count");
            grid.stats.hasSvdag = r.get<uint8_t>() != 0;
            for (uint32_t i = 0; i < n; ++i) {
                grid.stats.svoNodes.push_back(r.get<uint64_t>());
                grid.stats.svdagNodes.push_back(r.get<uint64_t>());
                grid.stats.storedNodes.push_back(r.get<uint64_t>());
            }
            r.expectEnd();
        }
        if (Section* s = find(g, SectionKind::Summary, false)) grid.summary = parseSummary(s->data, vs, what + " Summary");
    }
    for (const auto& [key, section] : byGrid)
        if (key.first >= gridCount) throw Error(sourceName + ": section for grid " + std::to_string(key.first) + " but the file has " + std::to_string(gridCount) + " grids");
    if (options.grid && first < range.first) scene.grids.erase(scene.grids.begin(), scene.grids.begin() + ptrdiff_t(range.first - first));  // its chain
    return scene;
}

std::vector<uint8_t> writeScene(const SsvdagScene& scene, const ContainerOptions& options) {
    return writeContainer(sceneToSections(scene), options);
}

SsvdagScene readScene(std::span<const uint8_t> bytes, const std::string& sourceName) { return readScene(bytes, sourceName, ReadOptions{}); }

SsvdagScene readScene(std::span<const uint8_t> bytes, const std::string& sourceName, const ReadOptions& options) {
    return sectionsToScene(readContainer(bytes, sourceName, /*unknownKinds=*/false, options.limits), sourceName, options);
}

SsvdagScene readSceneFile(const std::string& path) { return readSceneFile(path, ReadOptions{}); }

bool isHeaderSection(SectionKind kind) {
    switch (kind) {
        case SectionKind::DagInner:
        case SectionKind::DagLeaves:
        case SectionKind::InactiveInner:
        case SectionKind::InactiveLeaves:
        case SectionKind::Values:
        case SectionKind::InactiveValues:
        case SectionKind::ValueWindows:
        case SectionKind::InactiveValueWindows:
        case SectionKind::PredictedWindows:
        case SectionKind::InactivePredictedWindows:
        case SectionKind::PredictedValues:
        case SectionKind::InactivePredictedValues:
        case SectionKind::Normals: return false;
        default: return true;
    }
}

SsvdagScene readSceneFile(const std::string& path, const ReadOptions& options) {
    if (options.headersOnly && !options.frame && !options.grid)
        return sectionsToScene(readContainerFile(path, false, options.limits, [](SectionKind kind, uint32_t) { return isHeaderSection(kind); }), path, options);
    if (!options.frame && !options.grid) return sectionsToScene(readContainerFile(path, /*unknownKinds=*/false, options.limits), path, options);
    if (options.frame && options.grid) throw Error("internal error: a frame and a grid asked for at once");
    // One frame or grid: its sections only (and the file's FileInfo and Frames).
    const FrameList list = readFrameList(path);
    if (options.grid && *options.grid >= list.gridCount)
        throw Error(path + ": has " + std::to_string(list.gridCount) + " grid(s); grid " + std::to_string(*options.grid) + " asked for");
    GridRange range = options.frame ? frameGrids(list.frames, list.gridCount, *options.frame, path) : GridRange{*options.grid, *options.grid + 1};
    if (options.grid && !options.referencesByCaller) range.first = referenceChainStart(path, *options.grid, options.limits);  // and its values' reference chain (FORMAT.md 8.6)
    const uint32_t first = range.first, end = range.end;  // (named, for the lambdas)
    const auto keep = [first, end](SectionKind kind, uint32_t grid) {
        switch (kind) {
            case SectionKind::FileInfo:
            case SectionKind::Frames:
            case SectionKind::FileMetadata: return true;
            case SectionKind::FrameMetadata: return grid == first;
            default: return grid >= first && grid < end;
        }
    };
    std::vector<Section> sections = readContainerFile(path, /*unknownKinds=*/false, options.limits, keep);
    // The sections this frame's unchanged grids take from earlier frames.
    std::set<std::pair<uint32_t, uint32_t>> shared;  // (grid, kind)
    for (const Section& s : sections)
        if (s.kind == SectionKind::SameAs && s.grid >= first && s.grid < end)
            for (const SameAsEntry& e : parseSameAs(s.data, s.grid, path + ": SameAs of grid " + std::to_string(s.grid)))
                if (e.grid < first) shared.insert({e.grid, uint32_t(e.kind)});
    if (!shared.empty()) {
        std::vector<Section> more = readContainerFile(path, false, options.limits, [&](SectionKind kind, uint32_t grid) {
            return shared.contains({grid, uint32_t(kind)});
        });
        for (Section& s : more) sections.push_back(std::move(s));
    }
    return sectionsToScene(std::move(sections), path, options);
}

} // namespace vdbdag::format
