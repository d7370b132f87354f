// What a vdbdag::File (include/vdbdag/vdbdag.h) holds behind its public
// classes: each grid as read (DAGs inflated, value windows kept as stored)
// and each layer's value channel, decoded on first use.
#pragma once
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <vdbdag/vdbdag.h>

#include "src/attributes/PaletteChannel.h"
#include "src/format/SsvdagFile.h"

namespace vdbdag::detail {

// One layer (active or inactive) of a grid: its DAG and its values.
struct Layer {
    const encoding::CompactDag* dag = nullptr;
    // The entry of voxel (i, j, k) in attribute order (DESIGN.md invariant
    // 2), walking from where `path` left off; false when the layer has no
    // such voxel.
    bool find(int64_t i, int64_t j, int64_t k, Accessor::Path& path, uint64_t& entry) const;
    // Entry `entry`'s value (valueSize bytes); the channel is decoded the
    // first time.
    void value(uint64_t entry, uint8_t* out, size_t& hint) const;

    // Set by the file reader; the channel is built from them once.
    const format::EncodedGrid* grid = nullptr;
    bool inactive = false;
    std::string what;  // "FILE: grid 'NAME'"

private:
    void load() const;
    mutable std::once_flag loaded_;
    mutable bool palette_ = false;
    mutable attributes::PaletteChannel channel_;  // palette windows, or a palette of an older file
    mutable std::vector<uint8_t> flat_;           // predicted (integer) windows, decoded in attribute order
};

struct GridData {
    format::EncodedGrid grid;
    Layer active, inactive;
    unsigned valueSize = 0;
};

struct FileData {
    std::string path;
    std::vector<std::unique_ptr<GridData>> data;
    std::vector<Grid> grids;
    static std::shared_ptr<FileData> read(const std::string& path, const OpenLimits& limits);
};

} // namespace vdbdag::detail
