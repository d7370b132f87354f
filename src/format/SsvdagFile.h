// The content of an .ssvdag file: per grid its header (GridRecord without
// voxels), its compact DAG and its build statistics, mapped onto container
// sections (SsvdagContainer.h). Reading validates every section and the DAG
// itself before returning, so callers can walk the DAG without checks.
#pragma once
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "src/attributes/ColourQuantizer.h"
#include "src/attributes/NormalChannel.h"
#include "src/attributes/PaletteChannel.h"
#include "src/attributes/ScalarTolerance.h"
#include "src/attributes/ValueRange.h"
#include "src/attributes/ValueWindows.h"
#include "src/encoding/CompactDag.h"
#include "src/format/DagBounds.h"
#include "src/format/SsvdagContainer.h"
#include "src/volume/GridRecord.h"

namespace vdbdag::format {

// Per level s = 2..log2Size (index s-2): node counts of the sparse voxel
// octree, of the plain SVDAG (0 when not computed) and of the stored DAG.
struct DagStats {
    std::vector<uint64_t> svoNodes, svdagNodes, storedNodes;
    bool hasSvdag = false;
};

// What a grid's Summary section stores (docs/FORMAT.md 10.1): the facts
// `info` prints that would otherwise take the whole DAG and every value.
struct StoredSummary {
    std::optional<IndexBox> indexBox;  // of the active voxels; none when the active layer is empty
    uint64_t solidNodes = 0;           // DAG nodes that are whole active cubes (a .vdb's active tiles)
    // Each layer's attribute entries (each voxel of a brick, each solid node
    // once): what a reader weighs against its limits before it reads the DAG.
    uint64_t activeEntries = 0, inactiveEntries = 0;
    attributes::ValueRange activeRange;
};

// One layer of a grid (docs/FORMAT.md 6): the active voxels, or the
// inactive voxels and tiles whose value differs from the background. Its
// DAG, and its values in the forms a file or an encoder holds them:
// `attributes` flat in attribute order (valueSize bytes each; what an
// encoder produced, or a reader decoded), `values` palette-compressed (the
// traceable layout a reader builds, format/TraceableValues.h), `valueWindows`
// the ValueWindows or PredictedWindows payload an encoder writes instead of
// the palettes and a reader keeps as read (empty: `values` is written), and
// `predictedValues` a file's PredictedValues payload from before
// PredictedWindows (kept as read; the palettes are rebuilt from it).
struct EncodedLayer {
    uint64_t voxels = 0;  // tiles counted as their voxels
    encoding::CompactDag dag;
    std::vector<uint8_t> attributes;
    attributes::PaletteChannel values;
    attributes::ValueWindowsPayload valueWindows;
    std::vector<uint8_t> predictedValues;
};

struct EncodedGrid {
    GridRecord record;          // name, class, type, transform, descriptor, background; no voxels
    bool symmetry = true;       // SSVDAG (true) or plain SVDAG
    EncodedLayer active;        // the active voxels and tiles
    EncodedLayer inactive;      // inactive voxels and tiles off the background
    // The inactive layer is OpenVDB's signed flood fill of the active values
    // (src/volume/SignedFill.h): the file stores an InactiveSignedFill
    // section instead of it (docs/FORMAT.md 6.6) and a reader makes it again
    // from the active layer (inactive.voxels holds its voxel count either way).
    bool inactiveSignedFill = false;
    const EncodedLayer& layer(bool inactiveLayer) const { return inactiveLayer ? inactive : active; }
    EncodedLayer& layer(bool inactiveLayer) { return inactiveLayer ? inactive : active; }
    attributes::ToleranceReport lossy;  // what a lossy setting changed (mode Exact: nothing)
    // Colour grids encoded with --colour-bits: what the CIELAB clustering
    // changed (the values above already hold the representatives).
    std::optional<attributes::ColourReport> colour;
    // --normals K: one k-bit ONV per active attribute entry (NormalChannel.h:
    // decode entry i with normals->decode(i)). Absent unless asked for.
    std::optional<attributes::NormalChannel> normals;
    DagStats stats;
    // Its Summary section: as read (none in files written before it), or as
    // an encoder sets it (format::summaryToStore); written when present.
    std::optional<StoredSummary> summary;
};

// One frame of a sequence file (docs/FORMAT.md 4.3): the grids
// [firstGrid, firstGrid + gridCount) of the scene.
struct SceneFrame {
    int64_t number = 0;            // the frame number of its source (smoke.0042.vdb: 42)
    uint32_t firstGrid = 0, gridCount = 0;
    std::vector<uint8_t> metadata;  // its .vdb file's metadata (opaque, as fileMetadata)
};

struct SsvdagScene {
    std::vector<EncodedGrid> grids;
    std::vector<uint8_t> fileMetadata;  // Volume::fileMetadata (opaque); empty in a sequence
    // A sequence file's frames, in order, covering every grid; empty for a
    // file of one volume. A scene read with ReadOptions::frame is that frame
    // alone, as a file of one volume (its metadata in fileMetadata).
    std::vector<SceneFrame> frames;
};

// The traceable channel of a layer (palettes): format/TraceableValues.h.

std::vector<Section> sceneToSections(const SsvdagScene& scene);

// The raw payloads of a layer's DagLevels (or InactiveLevels) section and of
// a grid's DagStats section, as the writer stores them (docs/FORMAT.md).
std::vector<uint8_t> serializeDagLevels(const encoding::CompactDag& dag);
std::vector<uint8_t> serializeDagStats(const DagStats& stats);
// The Summary section's payload (docs/FORMAT.md 10.1), and its parse
// (throws Error naming `what`).
std::vector<uint8_t> serializeSummary(const StoredSummary& summary, unsigned valueSize);
StoredSummary parseSummary(std::span<const uint8_t> bytes, unsigned valueSize, const std::string& what);
SsvdagScene sectionsToScene(std::vector<Section> sections, const std::string& sourceName);
// What a reader builds beyond the values themselves.
struct ReadOptions {
    // (Integer channels, stored as predicted windows, are read into
    // `attributes`; their palettes, the traceable layout, are built where a
    // tracer needs them: format::traceableValues.)
    // Keep ValueWindows and PredictedWindows payloads as they are, in
    // EncodedGrid::valueWindows / inactiveValueWindows, with no attribute
    // array or channel: for readers that stream a layer window by window
    // (pipeline/LayerScatter.h). Only the directory is checked here.
    bool keepValueWindows = false;
    // Refuse what would expand past these (ReadLimits.h) before expanding it.
    ReadLimits limits;
    // How predicted windows are decoded (util::tbbParallelFor in the core
    // library's users; the reader library: one after another).
    attributes::ParallelFor parallel;
    // Read one frame of a sequence file (an index into its frames; a file
    // of one volume has frame 0 only): only its sections are read.
    std::optional<uint32_t> frame;
    // Read one grid (its index in the file) and only its sections: the
    // scene's grids are that one (the reader library's first use of a grid).
    // Not with `frame`. A grid whose values take an earlier grid's as their
    // reference (FORMAT.md 8.6) is read with its chain (those grids read
    // too, then dropped), unless `referencesByCaller`: then its layer's
    // referenceDistance is set and its `reference` left empty, for a caller
    // that holds the earlier grids itself (the reader library).
    std::optional<uint32_t> grid;
    bool referencesByCaller = false;
    // The grids' headers only (`info` of a file with Summary sections): each
    // layer's DagLevels (origin, size, levels; no inner words or leaves),
    // no values, no normals. The sections given may lack the rest.
    bool headersOnly = false;
    // A grid whose inside is a signed fill (EncodedGrid::inactiveSignedFill)
    // gets its inactive layer built as a DAG, as tracers and the reader
    // library walk it (format/InactiveSignedFill.h). Off: the layer stays
    // empty for a reader that makes the fill from the active voxels it
    // decodes anyway (pipeline::decodeGrid: a .vdb decode, 72 ms of
    // 752 less on the bunny level set).
    bool signedFillLayer = true;
};
SsvdagScene sectionsToScene(std::vector<Section> sections, const std::string& sourceName, const ReadOptions& options);

std::vector<uint8_t> writeScene(const SsvdagScene& scene, const ContainerOptions& options = {});
// The same bytes written to `out`, in bounded memory: the scene's DAGs,
// value payloads and descriptors are moved out of it as they are written
// (the grid headers, statistics and reports stay, for a report). Returns
// the bytes written.
uint64_t writeSceneReleasing(SsvdagScene& scene, std::ostream& out, const ContainerOptions& options = {});
SsvdagScene readScene(std::span<const uint8_t> bytes, const std::string& sourceName);
SsvdagScene readScene(std::span<const uint8_t> bytes, const std::string& sourceName, const ReadOptions& options);
// The sections a ReadOptions::headersOnly read of a file reads: all but
// the DAGs' inner words and leaves, the values and the normals.
bool isHeaderSection(SectionKind kind);
SsvdagScene readSceneFile(const std::string& path);
SsvdagScene readSceneFile(const std::string& path, const ReadOptions& options);

} // namespace vdbdag::format
