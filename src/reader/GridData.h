// What a vdbdag::File (include/vdbdag/vdbdag.h) holds behind its public
// classes: each grid's header as read on open, its DAGs and value payloads
// read when the grid is first used (GridData::load), and each layer's value
// channel, decoded on first use.
#pragma once
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include <vdbdag/vdbdag.h>

#include "src/attributes/PaletteChannel.h"
#include "src/attributes/PredictedWindows.h"
#include "src/format/SsvdagFile.h"

namespace vdbdag::detail {

struct GridData;

// One layer (active or inactive) of a grid: its DAG and its values.
struct Layer {
    const encoding::CompactDag* dag = nullptr;
    // The entry of voxel (i, j, k) in attribute order (DESIGN.md invariant
    // 2), walking from where `path` left off; false when the layer has no
    // such voxel.
    bool find(int64_t i, int64_t j, int64_t k, Accessor::Path& path, uint64_t& entry) const;
    // What the layer holds of the 4^3 brick whose minimum corner is (i, j,
    // k) (a multiple of 4 from the DAG's origin): nothing, one entry for
    // every voxel (a solid node), or a leaf's stored bits, mirror mask and
    // first entry. Walks as find does, from where `path` left off.
    struct Brick {
        enum Kind { kNone, kUniform, kLeaf } kind = kNone;
        uint64_t entry = 0;   // kUniform: the entry; kLeaf: that of its first stored bit
        uint64_t stored = 0;  // kLeaf
        unsigned mirror = 0;  // kLeaf
    };
    Brick brick(int64_t i, int64_t j, int64_t k, Accessor::Path& path) const;
    // Entry `entry`'s value (valueSize bytes); its window (or an older
    // file's channel) is decoded the first time. `hint` remembers the last
    // window or palette block.
    void value(uint64_t entry, uint8_t* out, size_t& hint) const { values(entry, 1, out, hint); }
    // The values of `count` consecutive entries from `first`.
    void values(uint64_t first, uint64_t count, uint8_t* out, size_t& hint) const;

    // Predicted window k's entries (decoded once, as values() decodes it).
    std::vector<uint8_t> window(size_t k) const;

    // Set by the file reader; the channel is built from them once.
    const format::EncodedGrid* grid = nullptr;
    bool inactive = false;
    std::string what;  // "FILE: grid 'NAME'"
    // The grid whose active windows this (active) layer's take as their
    // reference (a 4-D scan's volume before: FORMAT.md 8.6), when the file
    // was opened by its headers: its windows, decoded once by its own
    // layer, serve every grid that reads them.
    const GridData* referenceGrid = nullptr;

private:
    void load() const;
    void decodeWindow(size_t k) const;  // predicted window k, once
    mutable std::once_flag loaded_;
    mutable bool palette_ = false;
    mutable attributes::PaletteChannel channel_;  // palette windows, or a palette of an older file
    mutable std::vector<uint8_t> flat_;           // an older file's predicted values, in attribute order
    // Predicted windows (integers, floats, vectors), each decoded the first
    // time one of its entries is asked for: a lookup, a coarse level of
    // detail or a box decodes the windows it touches, not the channel, and
    // threads that touch different windows decode them at once.
    struct Windows {
        std::vector<uint8_t> spilled;  // the payload, when it was spilled to a scratch file
        std::span<const uint8_t> payload;
        std::vector<uint64_t> layout;              // encoding::attributeLayout
        std::vector<coding::BrickPlace> places;    // encoding::attributePlaces
        attributes::WindowDirectory directory;
        std::unique_ptr<std::once_flag[]> decoded;
        std::unique_ptr<std::vector<uint8_t>[]> values;  // per window, once decoded
    };
    mutable std::unique_ptr<Windows> windows_;
};

struct GridData {
    format::EncodedGrid grid;
    Layer active, inactive;
    unsigned valueSize = 0;
    // A file whose grids all have Summary sections (docs/FORMAT.md 10.1) is
    // opened by its headers: `grid` holds the record, the counts and the
    // summary, and load() reads the rest of grid `index` (its DAGs, values,
    // normals and reports) the first time the grid is walked, under the
    // limits the file was opened with. Otherwise everything is read on open.
    bool lazy = false;
    unsigned referenceDepth = 0;  // grids of its values' reference chain (FORMAT.md 8.6), checked on open
    std::string path;
    uint32_t index = 0;
    format::ReadLimits limits;
    void load() const;  // any thread; a failed load throws again next time

private:
    mutable std::once_flag loaded_;
};

struct FileData {
    std::string path;
    uint32_t formatVersion = 1;  // the container header's (docs/FORMAT.md 3.1)
    std::vector<std::unique_ptr<GridData>> data;
    std::vector<Grid> grids;
    std::vector<Frame> frames;
    bool sequence = false;
    static std::shared_ptr<FileData> read(const std::string& path, const OpenLimits& limits);
};

} // namespace vdbdag::detail
