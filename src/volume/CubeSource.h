// A grid read one aligned cube at a time: the input of the out-of-core
// encoder (pipeline/CubeEncoder.h), which never holds the whole grid. An
// implementation reads its file region by region (vdb_bridge's .vdb reader
// through OpenVDB's delayed loading) or slices a grid already in memory
// (RecordCubes, below). No OpenVDB here.
//
// A grid has two layers, each encoded as its own DAG: the active voxels and
// tiles, and the inactive ones whose value differs from the background
// (GridRecord). Cubes are 2^log2 voxels wide, placed from an origin that is
// a multiple of 4, so every 4^3 brick lies in exactly one cube.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "src/volume/GridRecord.h"

namespace vdbdag {

enum class Layer : uint8_t { Active, Inactive };

struct LayerSummary {
    uint64_t voxels = 0;  // tiles counted as their voxels (saturating)
    uint64_t bricks = 0;  // 4^3 bricks
    uint64_t tiles = 0;
    // Inclusive box (meaningless when empty()); extend() grows it.
    std::array<int64_t, 3> min{INT64_MAX, INT64_MAX, INT64_MAX}, max{INT64_MIN, INT64_MIN, INT64_MIN};
    unsigned largestTileLog2 = 2;                     // 2: no tiles
    bool empty() const { return bricks == 0 && tiles == 0; }
    // Sources that see every value while they summarise note them here:
    // when all have the same bits (uniform()), the layer's values need no
    // gather pass (a level set's inactive voxels are all its inside value).
    bool mixed = false;
    std::vector<uint8_t> uniformValue;
    bool uniform() const { return !mixed && !uniformValue.empty(); }
    void noteValues(std::span<const uint8_t> values, unsigned valueSize) {
        for (size_t at = 0; !mixed && valueSize && at + valueSize <= values.size(); at += valueSize) {
            if (uniformValue.empty()) uniformValue.assign(values.begin() + long(at), values.begin() + long(at + valueSize));
            else if (!std::equal(uniformValue.begin(), uniformValue.end(), values.begin() + long(at))) mixed = true;
        }
    }
    // The cube [x, x + size)^3 is in the layer.
    void extend(int64_t x, int64_t y, int64_t z, int64_t size) {
        const int64_t c[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) {
            if (c[a] < min[a]) min[a] = c[a];
            if (c[a] + size - 1 > max[a]) max[a] = c[a] + size - 1;
        }
    }
};

// One cube of a layer, in units of the cube size from the origin.
struct CubeCell {
    uint32_t x, y, z;
    bool operator==(const CubeCell&) const = default;
};
struct CubeLoad {
    CubeCell cell;
    uint64_t bricks = 0;  // bricks in the cube (tiles no larger than the cube count as one brick)
};

class CubeSource;

// The exact normals of a grid's active voxels (`encode --normals`), as a
// source of their own: the same cubes as the grid's, each active voxel's
// value its unit normal (3 x float; zero: no direction); and how they were
// made (GridNormals).
struct NormalSource {
    CubeSource* cubes = nullptr;
    bool fromNormalGrid = false;  // false: the level set's gradient
    uint64_t oneSided = 0;        // gradient entries where a band edge forced a one-sided difference
};

class CubeSource {
public:
    virtual ~CubeSource() = default;
    // The grid's normals (`encode --normals`): a grid in memory gives its
    // own (GridRecord::normals), a .vdb read region by region computes them
    // cube by cube with a one-voxel halo (VdbCubes.h); cubes null when the
    // grid has none, which the encoder then stores none of. None at all
    // from a source that cannot give them (a dense scan's), which the
    // encoder refuses for --normals.
    virtual std::optional<NormalSource> normals() { return std::nullopt; }
    // Whether the inactive layer is exactly what OpenVDB's signed flood
    // fill makes of the active voxels (signedFillInactive, SignedFill.h):
    // then the encoder stores none and the reader makes it again. Known
    // once the source is open; false where a source cannot tell.
    virtual bool inactiveIsSignedFill() { return false; }
    // Name, class, type, transform, descriptor, background; no voxels.
    virtual const GridRecord& header() const = 0;
    virtual LayerSummary summary(Layer layer) = 0;
    // The non-empty cubes of 2^log2 from `origin` (any order) and the tiles
    // larger than a cube (with their values, input order).
    virtual std::vector<CubeLoad> cubes(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2) = 0;
    virtual void largeTiles(Layer layer, unsigned log2, GridTopology& tiles, LayerValues& values) = 0;
    // A pass reads each cube of `cubes` once, in any order; between
    // beginPass and endPass a source may free what a read cube used.
    virtual void beginPass(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2, bool withValues) = 0;
    // The bricks and the tiles no larger than the cube inside cube `cell`,
    // with their values (input order, GridRecord's LayerValues convention)
    // unless the pass is without values.
    virtual void read(const CubeCell& cell, GridTopology& topology, LayerValues& values) = 0;
    virtual void endPass() = 0;
};

// For implementations: the tiles of `all` larger than 2^log2, with their
// values (`valueSize` bytes each in `values`; none when 0).
void selectLargeTiles(const GridTopology& all, const LayerValues& values, unsigned valueSize, unsigned log2, GridTopology& tiles,
                      LayerValues& tileValues);

// A CubeSource over a grid in memory (for dense scans, tests and the
// in-core path). Keeps a reference: `grid` must outlive it.
std::unique_ptr<CubeSource> recordCubes(const GridRecord& grid);

} // namespace vdbdag
