// vdbdag::File and vdbdag::Grid (include/vdbdag/vdbdag.h): a file read with
// its value windows kept as stored, each channel decoded on first use.
#include <vdbdag/vdbdag.h>

#include <algorithm>
#include <cstring>
#include <fstream>

#include "src/attributes/PredictedWindows.h"
#include "src/attributes/ValueWindows.h"
#include "src/encoding/AttributeLayout.h"
#include "src/format/DagBounds.h"
#include "src/format/ReadLimits.h"
#include "src/format/SsvdagContainer.h"
#include "src/reader/GridData.h"

namespace vdbdag {

int readableFormatVersion() { return int(format::kLatestFormatVersion); }

namespace detail {

void GridData::load() const {
    if (!lazy) return;
    std::call_once(loaded_, [&] {
        format::ReadOptions options;
        options.keepValueWindows = true;
        options.limits = limits;
        options.grid = index;
        options.referencesByCaller = true;  // Layer::referenceGrid
        format::SsvdagScene scene = format::readSceneFile(path, options);
        if (scene.grids.size() != 1) throw Error(path + ": grid " + std::to_string(index) + " could not be read alone");
        format::EncodedGrid& from = scene.grids[0];
        // What no reader touched before now (the once flag orders it before
        // every walk); the header, the counts and the summary stay as read.
        auto& to = const_cast<format::EncodedGrid&>(grid);
        for (const bool inactive : {false, true}) {  // each layer but its voxel count, which readers may be reading
            format::EncodedLayer& layer = to.layer(inactive);
            format::EncodedLayer& read = from.layer(inactive);
            layer.dag = std::move(read.dag);
            layer.attributes = std::move(read.attributes);
            layer.values = std::move(read.values);
            layer.valueWindows = std::move(read.valueWindows);
            layer.predictedValues = std::move(read.predictedValues);
        }
        to.lossy = from.lossy;
        to.colour = std::move(from.colour);
        to.normals = std::move(from.normals);
        to.stats = std::move(from.stats);
    });
}

void Layer::load() const {
    std::call_once(loaded_, [&] {
        const unsigned vs = valueSize(grid->record.valueType);
        const format::EncodedLayer& layer = grid->layer(inactive);
        const attributes::ValueWindowsPayload& windows = layer.valueWindows;
        const attributes::PaletteChannel& channel = layer.values;
        const std::vector<uint8_t>& attributes = layer.attributes;
        if (!windows.empty() && windows.predicted) {
            auto w = std::make_unique<Windows>();
            if (windows.file) w->spilled = windows.load();
            w->payload = windows.file ? std::span<const uint8_t>(w->spilled) : std::span<const uint8_t>(windows.bytes);
            w->layout = encoding::attributeLayout(*dag);
            w->places = encoding::attributePlaces(*dag, vs);
            w->directory = attributes::readPredictedWindowDirectory(w->payload, vs, w->layout, what + " predicted windows");
            if (referenceGrid) {  // the same DAG and windows as the grid it takes its reference from (FORMAT.md 8.6)
                referenceGrid->load();
                const Layer& theirs = referenceGrid->active;
                theirs.load();
                if (*dag != *theirs.dag || !theirs.windows_)
                    throw Error(what + ": takes its values' reference from a grid whose active voxels or values are not this grid's kind");
                if (!attributes::sameWindowCuts(theirs.windows_->directory, w->directory))
                    throw Error(what + ": takes its values' reference from a grid whose values are cut into other windows");
            }
            w->decoded = std::make_unique<std::once_flag[]>(w->directory.windows.size());
            w->values = std::make_unique<std::vector<uint8_t>[]>(w->directory.windows.size());
            windows_ = std::move(w);
        } else if (!windows.empty()) {
            channel_ = attributes::decodeValueWindows(windows.load(), what + " value windows");
            palette_ = true;
        } else if (channel.entryCount) {  // an older file's palette section
            channel_ = channel;
            palette_ = true;
        } else {  // an older file's predicted values, decoded as read
            flat_ = attributes;
        }
    });
}

void Layer::decodeWindow(size_t k) const {
    Windows& w = *windows_;
    std::call_once(w.decoded[k], [&] {
        // A series' reference (FORMAT.md 8.6): the grid before's own layer
        // (opened by headers), else the chain the grid's read built.
        attributes::ReferenceWindow reference;
        if (referenceGrid)
            reference = [this](size_t r) {
                referenceGrid->load();
                return referenceGrid->active.window(r);
            };
        else
            reference = attributes::referenceWindows(grid->layer(inactive).valueWindows.reference, w.layout, w.places);
        std::vector<uint8_t> decoded = attributes::decodePredictedWindow(w.payload, w.directory, k, w.layout, what + " predicted windows", w.places, reference);
        if (decoded.size() != w.directory.windows[k].entries * valueSize(grid->record.valueType))
            throw Error(what + " predicted windows window " + std::to_string(k) + ": decoded to the wrong size");
        w.values[k] = std::move(decoded);
    });
}

std::vector<uint8_t> Layer::window(size_t k) const {
    load();
    if (!windows_ || k >= windows_->directory.windows.size()) throw Error(what + ": has no predicted window " + std::to_string(k) + " for a grid that takes it as reference");
    decodeWindow(k);
    return windows_->values[k];
}

void Layer::values(uint64_t first, uint64_t count, uint8_t* out, size_t& hint) const {
    load();
    const unsigned vs = valueSize(grid->record.valueType);
    if (vs == 0 || count == 0) return;
    if (palette_) {
        for (uint64_t e = first; e < first + count; ++e, out += vs) channel_.lookup(e, out, hint);
        return;
    }
    if (windows_) {
        Windows& w = *windows_;
        const auto& list = w.directory.windows;
        while (count > 0) {  // a run of entries may span windows
            size_t k = hint;
            if (k >= list.size() || first < list[k].firstEntry || first - list[k].firstEntry >= list[k].entries) {
                const auto after = std::upper_bound(list.begin(), list.end(), first, [](uint64_t e, const auto& window) { return e < window.firstEntry; });
                k = size_t(after - list.begin()) - 1;  // the directory's first window starts at entry 0
                if (after == list.begin() || first - list[k].firstEntry >= list[k].entries)
                    throw Error(what + ": value entry " + std::to_string(first) + " is past the channel's end");
                hint = k;
            }
            decodeWindow(k);
            const uint64_t at = first - list[k].firstEntry, n = std::min(count, list[k].entries - at);
            std::memcpy(out, w.values[k].data() + at * vs, n * vs);
            out += n * vs, first += n, count -= n;
        }
        return;
    }
    if (first > flat_.size() / vs || count > flat_.size() / vs - first)
        throw Error(what + ": value entry " + std::to_string(first + count - 1) + " is past the channel's end");
    std::memcpy(out, flat_.data() + first * vs, count * vs);
}

static_assert(OpenLimits{}.maxVoxels == format::kDefaultMaxVoxels, "the public default is the command line's");

std::shared_ptr<FileData> FileData::read(const std::string& path, const OpenLimits& limits) {
    format::ReadOptions options;
    options.keepValueWindows = true;  // decoded when first asked for
    options.limits.maxVoxels = limits.maxVoxels;
    options.limits.maxMemory = limits.maxMemory ? limits.maxMemory : format::defaultReadMemory();
    // The headers first; with a Summary for every grid the rest waits for
    // each grid's first use (GridData::load), and what the whole file
    // would take is weighed now, as a whole read weighs it, so that a file
    // beyond the limits is still refused on open.
    format::ReadOptions headers;
    headers.headersOnly = true;
    headers.limits = options.limits;
    format::SsvdagScene scene = format::readSceneFile(path, headers);
    const bool lazy = std::all_of(scene.grids.begin(), scene.grids.end(), [](const format::EncodedGrid& g) { return g.summary.has_value(); });
    if (lazy) {
        uint64_t bytes = 0;
        for (const format::Section& s : format::storedSectionsOf(path))
            if (format::isKnownKind(s.kind)) bytes = format::saturatingAdd(bytes, s.stored->rawBytes);
        for (const format::EncodedGrid& g : scene.grids) {
            const std::string what = path + ": grid '" + g.record.name + "'";
            format::checkVoxels(options.limits, g.summary->activeEntries, what + " active layer");
            format::checkVoxels(options.limits, g.summary->inactiveEntries, what + " inactive layer");
        }
        format::checkMemory(options.limits, bytes, path, "its sections");
    } else {
        scene = format::readSceneFile(path, options);
    }
    auto file = std::make_shared<FileData>();
    file->path = path;
    file->sequence = !scene.frames.empty();
    {  // the container's version, from its header (the read above checked it)
        std::ifstream in(path, std::ios::binary);
        uint8_t head[12] = {};
        in.read(reinterpret_cast<char*>(head), sizeof head);
        std::memcpy(&file->formatVersion, head + 8, 4);
    }
    for (const format::SceneFrame& f : scene.frames) file->frames.push_back({f.number, f.firstGrid, f.gridCount});
    if (scene.frames.empty()) file->frames.push_back({0, 0, scene.grids.size()});
    for (format::EncodedGrid& g : scene.grids) {
        auto data = std::make_unique<GridData>();
        data->grid = std::move(g);
        data->valueSize = valueSize(data->grid.record.valueType);
        const std::string what = path + ": grid '" + data->grid.record.name + "'";
        if (data->valueSize > sizeof(Accessor::Path::value)) throw Error(what + ": a " + std::to_string(data->valueSize) + "-byte value type is not supported");
        if (data->grid.record.background.size() != data->valueSize)
            throw Error(what + ": its background holds " + std::to_string(data->grid.record.background.size()) + " bytes, expected " +
                        std::to_string(data->valueSize));
        data->active.dag = &data->grid.active.dag;
        data->active.grid = &data->grid;
        data->active.what = what;
        data->inactive.dag = &data->grid.inactive.dag;
        data->inactive.grid = &data->grid;
        data->inactive.inactive = true;
        data->inactive.what = what + " inactive values";
        data->lazy = lazy;
        if (const uint32_t d = data->grid.active.valueWindows.referenceDistance; lazy && d) {  // FORMAT.md 8.6, checked as the scene reader checks it
            const size_t g = file->data.size();
            size_t frameFirst = 0;
            for (const Frame& f : file->frames)
                if (f.firstGrid <= g) frameFirst = f.firstGrid;
            if (d > g - frameFirst) throw Error(what + ": its values take grid " + std::to_string(int64_t(g) - d) + ", not an earlier grid of its frame, as their reference");
            const GridData* reference = file->data[g - d].get();
            if (reference->grid.record.valueType != data->grid.record.valueType)
                throw Error(what + ": its values take grid " + std::to_string(g - d) + ", of another value type, as their reference");
            data->referenceDepth = reference->referenceDepth + 1;
            if (data->referenceDepth > attributes::kMaxReferenceChain)
                throw Error(what + ": takes its values' reference through more than " + std::to_string(attributes::kMaxReferenceChain) + " grids");
            data->active.referenceGrid = reference;
        }
        data->path = path;
        data->index = uint32_t(file->grids.size());
        data->limits = options.limits;
        file->grids.push_back(Grid(data.get()));
        file->data.push_back(std::move(data));
    }
    return file;
}

} // namespace detail

File File::open(const std::string& path, const OpenLimits& limits) { return File(detail::FileData::read(path, limits)); }
File File::open(const std::string& path) { return open(path, OpenLimits{}); }

size_t File::gridCount() const { return data_->grids.size(); }

const Grid& File::grid(size_t index) const {
    if (index >= data_->grids.size())
        throw Error(data_->path + ": no grid " + std::to_string(index) + " (the file holds " + std::to_string(data_->grids.size()) + ")");
    return data_->grids[index];
}

const Grid& File::grid(const std::string& name) const {
    for (size_t g = 0; g < data_->grids.size(); ++g)
        if (data_->grids[g].name() == name) return data_->grids[g];
    throw Error(data_->path + ": no grid named '" + name + "'");
}

const std::vector<Frame>& File::frames() const { return data_->frames; }
bool File::isSequence() const { return data_->sequence; }

const Grid& File::grid(const std::string& name, int64_t frame) const {
    for (const Frame& f : data_->frames) {
        if (f.number != frame) continue;
        for (size_t g = f.firstGrid; g < f.firstGrid + f.gridCount; ++g)
            if (data_->grids[g].name() == name) return data_->grids[g];
        throw Error(data_->path + ": frame " + std::to_string(frame) + " has no grid named '" + name + "'");
    }
    throw Error(data_->path + ": has no frame " + std::to_string(frame));
}

uint32_t File::formatVersion() const { return data_->formatVersion; }
const std::string& File::path() const { return data_->path; }

const std::string& Grid::name() const { return data_->grid.record.name; }
const std::string& Grid::gridClass() const { return data_->grid.record.gridClass; }
std::string Grid::valueType() const { return valueTypeName(data_->grid.record.valueType); }
unsigned Grid::valueSize() const { return data_->valueSize; }
uint64_t Grid::activeVoxelCount() const { return data_->grid.active.voxels; }
uint64_t Grid::inactiveVoxelCount() const { return data_->grid.inactive.voxels; }
std::array<double, 16> Grid::indexToWorld() const { return data_->grid.record.indexToWorld; }

IndexBBox Grid::indexBBox() const {
    IndexBBox box;
    if (data_->grid.summary) {  // the DAG's own bounds, stored
        if (const auto& b = data_->grid.summary->indexBox) box.min = b->min, box.max = b->max;
        return box;
    }
    data_->load();
    if (const auto b = format::dagBounds(data_->grid.active.dag)) {
        box.min = b->min;
        box.max = b->max;
    }
    return box;
}

void Grid::backgroundBytes(void* out) const {
    const std::vector<uint8_t>& b = data_->grid.record.background;
    if (b.size() != data_->valueSize) throw Error("grid '" + name() + "': its background holds " + std::to_string(b.size()) + " bytes");
    if (!b.empty()) std::memcpy(out, b.data(), b.size());
}

} // namespace vdbdag
