// See VdbCubes.h. Per grid, a summary pass records for every leaf which of
// its 8 bricks hold voxels of each layer (the inactive layer needs the
// values, so that pass loads every buffer, a chunk of leaves at a time,
// dropping them as it goes); the active and inactive tiles are kept in
// memory (they carry one value each). A cube pass then indexes the fresh
// tree's leaves by cube and reads each cube's bricks on demand.
#include "vdb_bridge/VdbCubes.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <tuple>
#include <unordered_map>

#include <malloc.h>

#include <openvdb/io/GridDescriptor.h>
#include <openvdb/openvdb.h>
#include <tbb/parallel_for.h>

#include "src/util/Error.h"
#include "src/util/MappedPages.h"
#include "src/util/ScratchFile.h"
#include "src/volume/SignedFill.h"
#include "vdb_bridge/detail/ImportGrids.h"
#include "vdb_bridge/detail/LeafBricks.h"
#include "vdb_bridge/detail/LeafSignedFill.h"
#include "vdb_bridge/detail/NormalEstimation.h"
#include "vdb_bridge/detail/OpenVdbSupport.h"
#include "vdb_bridge/detail/VdbFile.h"
#include "vdb_bridge/detail/VdbFileLayout.h"

namespace vdbdag::bridge {
namespace {

struct CellLess {
    bool operator()(const CubeCell& a, const CubeCell& b) const { return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x); }
};

CubeCell cellOf(const std::array<int64_t, 3>& origin, unsigned log2, int64_t x, int64_t y, int64_t z) {
    return {uint32_t(uint64_t(x - origin[0]) >> log2), uint32_t(uint64_t(y - origin[1]) >> log2), uint32_t(uint64_t(z - origin[2]) >> log2)};
}

// Hands the heap's free pages back to the system after a pass (glibc keeps
// them otherwise, and the resident size is what a memory limit is held to).
void releaseFreedMemory() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

constexpr size_t kLeafChunk = 8192;  // leaves loaded at once by the summary pass

struct CoordHash {
    size_t operator()(const openvdb::Coord& c) const {
        return size_t((uint64_t(uint32_t(c.x())) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(uint32_t(c.y())) * 0xC2B2AE3D27D4EB4Full) ^
                      (uint64_t(uint32_t(c.z())) * 0x165667B19E3779F9ull));
    }
};

using detail::NormalsOf;

template <typename GridT, bool hasValues>
class VdbGridCubes final : public CubeSource {
    using TreeT = typename GridT::TreeType;
    using LeafT = typename TreeT::LeafNodeType;
    using ValueT = typename GridT::ValueType;

public:
    VdbGridCubes(std::string path, std::string uniqueName, GridRecord header, typename GridT::Ptr grid, std::shared_ptr<ScratchFile> scratch,
                 NormalsOf normals = NormalsOf::None)
        : path_(std::move(path)), uniqueName_(std::move(uniqueName)), header_(std::move(header)), scratch_(std::move(scratch)),
          normalKind_(normals), map_(grid->transform().baseMap()) {
        // OpenVDB's delayed loading (LeafBuffer::doLoad) leaves a leaf whose
        // values ran out of memory while they were read flagged out-of-core
        // over its value array; destroying that leaf then frees a FileInfo
        // that is not one ("free(): invalid pointer"). The encode fails
        // anyway, so after a failure the grid is never destroyed: the holder
        // is allocated before anything can fail, and leaked.
        auto holder = std::make_unique<typename GridT::Ptr>();
        try {
            if (normals == NormalsOf::Gradient) bandEdges_ = detail::countBandEdges(*grid);
            summarise(*grid);
        } catch (...) {
            *holder = std::move(grid);
            (void)holder.release();
            throw;
        }
        grid.reset();
        releaseFreedMemory();
    }

    const GridRecord& header() const override { return header_; }
    LayerSummary summary(Layer layer) override { return summary_[int(layer)]; }
    bool inactiveIsSignedFill() override { return signedFill_; }

    std::optional<NormalSource> normals() override {
        if (normalKind_ == NormalsOf::None) return NormalSource{};  // none to store for this grid
        if constexpr (hasValues) {
            if (!normalCubes_) normalCubes_ = std::make_unique<NormalCubes>(*this);
            return NormalSource{normalCubes_.get(), normalKind_ == NormalsOf::Vectors, normalCubes_->oneSided()};
        }
        return NormalSource{};
    }

    std::vector<CubeLoad> cubes(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2) override {
        std::map<CubeCell, uint64_t, CellLess> counts;
        for (const LeafInfo& leaf : leaves_)
            for (uint8_t bits = leaf.occupancy[int(layer)]; bits; bits &= uint8_t(bits - 1)) {
                const openvdb::Coord c = detail::brickCorner(leaf.origin, unsigned(std::countr_zero(bits)));
                ++counts[cellOf(origin, log2, c.x(), c.y(), c.z())];
            }
        for (const Tile& t : tiles_[int(layer)].tiles)
            if (t.log2Size <= log2) ++counts[cellOf(origin, log2, t.x, t.y, t.z)];
        std::vector<CubeLoad> out;
        out.reserve(counts.size());
        for (const auto& [cell, n] : counts) out.push_back({cell, n});
        return out;
    }

    void largeTiles(Layer layer, unsigned log2, GridTopology& tiles, LayerValues& values) override {
        selectLargeTiles(tiles_[int(layer)], tileValues_[int(layer)], valueSize(header_.valueType), log2, tiles, values);
    }

    void beginPass(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2, bool withValues) override {
        layer_ = layer;
        withValues_ = withValues && hasValues;
        index_ = cubeIndex(layer, origin, log2);
    }

    void read(const CubeCell& cell, GridTopology& topology, LayerValues& values) override {
        topology = {};
        values = {};
        const auto it = index_.find(cell);
        if (it == index_.end()) return;
        const unsigned vs = withValues_ ? valueSize(header_.valueType) : 0;
        std::vector<uint8_t> buffer;
        for (const auto& [leafIndex, bricks] : it->second.leaves) {
            const LeafInfo& leaf = leaves_[leafIndex];
            // Only what the pass needs: the masks, up to the active values,
            // or all of it.
            const size_t masksEnd = size_t(std::popcount(leaf.occupancy[0]) + std::popcount(leaf.occupancy[1])) * 8;
            const size_t used = !vs ? masksEnd : layer_ == Layer::Active ? leaf.activeEnd : leaf.recordSize;
            const std::span<const uint8_t> record = scratch_->view(leaf.recordOffset, used, buffer);
            // Record: the masks of the occupied active bricks, then of the
            // inactive ones (brick order), then the active values, then the
            // inactive values (LeafBricks.h order).
            const uint8_t occupancy[2] = {leaf.occupancy[0], leaf.occupancy[1]};
            const unsigned l = unsigned(layer_);
            const size_t maskBase = l == 0 ? 0 : size_t(std::popcount(occupancy[0]));
            const uint64_t* masks = reinterpret_cast<const uint64_t*>(record.data());
            size_t valueCursor = size_t(std::popcount(occupancy[0]) + std::popcount(occupancy[1])) * 8;
            if (l == 1)
                for (int k = 0; k < std::popcount(occupancy[0]); ++k) valueCursor += size_t(std::popcount(mask(masks, size_t(k)))) * valueSize(header_.valueType);
            unsigned rank = 0;
            for (unsigned b = 0; b < 8; ++b) {
                if (!((occupancy[l] >> b) & 1u)) continue;
                const uint64_t m = mask(masks, maskBase + rank++);
                const size_t n = size_t(std::popcount(m)) * valueSize(header_.valueType);
                if ((bricks >> b) & 1u) {
                    const openvdb::Coord c = detail::brickCorner(leaf.origin, b);
                    topology.bricks.push_back({c.x(), c.y(), c.z(), m});
                    if (vs) values.bricks.insert(values.bricks.end(), record.begin() + long(valueCursor), record.begin() + long(valueCursor + n));
                }
                valueCursor += n;
            }
        }
        const GridTopology& tiles = tiles_[int(layer_)];
        const LayerValues& tileValues = tileValues_[int(layer_)];
        for (size_t t : it->second.tiles) {
            topology.tiles.push_back(tiles.tiles[t]);
            if (vs) values.tiles.insert(values.tiles.end(), tileValues.tiles.begin() + long(t * vs), tileValues.tiles.begin() + long((t + 1) * vs));
        }
        index_.erase(it);
    }

    void endPass() override {
        index_.clear();
        releaseFreedMemory();
    }

private:
    struct LeafInfo {
        openvdb::Coord origin;
        uint8_t occupancy[2];  // per layer: bit b = brick b holds voxels
        uint32_t recordSize;   // the leaf's bricks in the scratch file
        uint32_t activeEnd;    // ... of which the masks and active values
        uint64_t recordOffset;
    };
    static uint64_t mask(const uint64_t* masks, size_t k) {
        uint64_t m;
        std::memcpy(&m, masks + k, sizeof m);
        return m;
    }
    // Notes a leaf's values in the layers' summaries: its first value of
    // each layer, or that the layer is mixed.
    void noteLeafValues(const std::vector<uint8_t>& record, const LeafInfo& leaf, uint8_t sameValues) {
        const unsigned vs = valueSize(header_.valueType);
        const size_t masksEnd = size_t(std::popcount(leaf.occupancy[0]) + std::popcount(leaf.occupancy[1])) * 8;
        const size_t begins[2] = {masksEnd, leaf.activeEnd}, ends[2] = {leaf.activeEnd, record.size()};
        for (int l = 0; l < 2; ++l) {
            if (begins[l] == ends[l] || summary_[l].mixed) continue;
            if (!((sameValues >> l) & 1u)) summary_[l].mixed = true;
            else summary_[l].noteValues(std::span<const uint8_t>(record).subspan(begins[l], vs), vs);
        }
    }
    struct CubeIndex {
        std::vector<std::pair<size_t, uint8_t>> leaves;  // (leaf, its bricks in this cube)
        std::vector<size_t> tiles;
    };
    using CubeIndexMap = std::map<CubeCell, CubeIndex, CellLess>;
    // Each cube's leaves (with their bricks in it) and tiles of `layer`.
    CubeIndexMap cubeIndex(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2) const {
        CubeIndexMap index;
        for (size_t i = 0; i < leaves_.size(); ++i) {
            std::map<CubeCell, uint8_t, CellLess> cells;
            for (uint8_t bits = leaves_[i].occupancy[int(layer)]; bits; bits &= uint8_t(bits - 1)) {
                const unsigned b = unsigned(std::countr_zero(bits));
                const openvdb::Coord c = detail::brickCorner(leaves_[i].origin, b);
                cells[cellOf(origin, log2, c.x(), c.y(), c.z())] |= uint8_t(1u << b);
            }
            for (const auto& [cell, bricks] : cells) index[cell].leaves.push_back({i, bricks});
        }
        const GridTopology& tiles = tiles_[int(layer)];
        for (size_t t = 0; t < tiles.tiles.size(); ++t)
            if (tiles.tiles[t].log2Size <= log2) index[cellOf(origin, log2, tiles.tiles[t].x, tiles.tiles[t].y, tiles.tiles[t].z)].tiles.push_back(t);
        return index;
    }

    // The active voxels of leaves read back from the scratch file, looked
    // up as OpenVDB's probeValue would: a voxel of a leaf is active if its
    // brick's mask says so; where no leaf is, an active tile may hold it.
    class Neighbourhood {
    public:
        explicit Neighbourhood(const VdbGridCubes& grid) : grid_(grid) {}
        // Leaf `i` (and, with `around`, the leaves beside its six faces):
        // every voxel one step from one of its voxels is then answered.
        void load(size_t i, bool withValues, bool around) {
            loadOne(grid_.leaves_[i].origin, withValues);
            if (!around) return;
            for (int axis = 0; axis < 3; ++axis)
                for (int step : {-8, 8}) {
                    openvdb::Coord o = grid_.leaves_[i].origin;
                    o[axis] += step;
                    loadOne(o, withValues);
                }
        }
        // The active tile holding `c` (OpenVDB's probeValue where no leaf is):
        // its value, or false.
        bool activeTile(const openvdb::Coord& c, ValueT& value) const {
            for (const auto& [log2, tiles] : grid_.activeTileAt_) {
                const int32_t low = ~((int32_t(1) << log2) - 1);
                const auto t = tiles.find(openvdb::Coord(c.x() & low, c.y() & low, c.z() & low));
                if (t == tiles.end()) continue;
                value = detail::valueFromBytes<ValueT>(grid_.tileValues_[0].tiles.data() + t->second * sizeof(ValueT));
                return true;
            }
            return false;
        }
        // The active voxels of brick b of the loaded leaf at `origin`.
        uint64_t brickMask(const openvdb::Coord& origin, unsigned b) const { return leaves_.at(origin).masks[b]; }

        // The loaded leaf at `origin` and, with `faces`, the voxels beside
        // its six faces as probeValue answers them (detail::haloIndex).
        struct Block {
            std::array<ValueT, 1000> value{};
            std::array<uint8_t, 1000> on{};
        };
        void fill(const openvdb::Coord& origin, Block& block, bool faces) const {
            block.on.fill(0);
            const LeafData& leaf = leaves_.at(origin);
            for (unsigned b = 0; b < 8; ++b) {
                const openvdb::Coord corner = detail::brickCorner(openvdb::Coord(0), b);
                size_t n = leaf.firstValue[b];
                for (uint64_t bits = leaf.masks[b]; bits; bits &= bits - 1, ++n) {
                    const int bit = std::countr_zero(bits);
                    const size_t i = detail::haloIndex(corner.x() + (bit & 3), corner.y() + ((bit >> 2) & 3), corner.z() + (bit >> 4));
                    block.on[i] = 1;
                    block.value[i] = detail::valueFromBytes<ValueT>(leaf.values.data() + n * sizeof(ValueT));
                }
            }
            if (!faces) return;
            detail::forEachHaloFace([&](const openvdb::Coord& offset, auto&& cells) {
                const auto beside = leaves_.find(origin + offset);  // loaded with this leaf when it exists (load)
                ValueT tileValue{};
                const bool tileOn = beside == leaves_.end() && activeTile(origin + offset, tileValue);  // no leaf: one tile (or none) holds it all
                cells([&](const openvdb::Coord& l) {
                    const size_t i = detail::haloIndex(l.x(), l.y(), l.z());
                    if (beside == leaves_.end()) block.on[i] = tileOn, block.value[i] = tileValue;
                    else block.on[i] = beside->second.voxel(origin + l, block.value[i]);
                });
            });
        }

    private:
        struct LeafData {
            uint64_t masks[8] = {};       // brick b's active voxels
            uint32_t firstValue[8] = {};  // brick b's first active value
            std::vector<uint8_t> values;  // the leaf's active values, brick order
            // Voxel c of this leaf: whether it is active, and its value.
            bool voxel(const openvdb::Coord& c, ValueT& value) const {
                const unsigned b = unsigned((c.x() >> 2) & 1) | unsigned((c.y() >> 2) & 1) << 1 | unsigned((c.z() >> 2) & 1) << 2;
                const unsigned bit = unsigned(c.x() & 3) + 4 * unsigned(c.y() & 3) + 16 * unsigned(c.z() & 3);
                if (!((masks[b] >> bit) & 1u)) return false;
                const size_t n = firstValue[b] + size_t(std::popcount(masks[b] & ((uint64_t(1) << bit) - 1)));
                value = detail::valueFromBytes<ValueT>(values.data() + n * sizeof(ValueT));
                return true;
            }
        };
        void loadOne(const openvdb::Coord& origin, bool withValues) {
            if (leaves_.count(origin)) return;
            const auto at = grid_.leafAt_.find(origin);
            if (at == grid_.leafAt_.end()) return;  // no leaf: a tile or nothing
            const LeafInfo& leaf = grid_.leaves_[at->second];
            const unsigned vs = valueSize(grid_.header_.valueType);
            const size_t masksEnd = size_t(std::popcount(leaf.occupancy[0]) + std::popcount(leaf.occupancy[1])) * 8;
            const std::span<const uint8_t> record = grid_.scratch_->view(leaf.recordOffset, withValues ? leaf.activeEnd : masksEnd, buffer_);
            LeafData data;
            uint32_t value = 0, rank = 0;
            for (unsigned b = 0; b < 8; ++b) {
                if (!((leaf.occupancy[0] >> b) & 1u)) continue;
                data.masks[b] = mask(reinterpret_cast<const uint64_t*>(record.data()), rank++);
                data.firstValue[b] = value;
                value += uint32_t(std::popcount(data.masks[b]));
            }
            if (withValues) data.values.assign(record.begin() + long(masksEnd), record.begin() + long(masksEnd + size_t(value) * vs));
            leaves_.emplace(origin, std::move(data));
        }
        const VdbGridCubes& grid_;
        std::unordered_map<openvdb::Coord, LeafData, CoordHash> leaves_;
        std::vector<uint8_t> buffer_;
    };

    // The normals as a source over the grid's own cubes (NormalSource):
    // each active voxel's and tile's value is its normal (3 x float),
    // computed from the cube's leaves and the leaves beside them.
    class NormalCubes final : public CubeSource {
    public:
        explicit NormalCubes(VdbGridCubes& grid) : grid_(grid), header_(grid.header_) {
            grid.indexNeighbours();
            header_.valueType = ValueType::Vec3S;
            header_.background.assign(sizeof(detail::NormalVector), 0);
            const GridTopology& tiles = grid.tiles_[0];
            tileNormals_.tiles.resize(tiles.tiles.size() * sizeof(detail::NormalVector));
            const Neighbourhood around(grid);  // a tile's centre and its neighbours lie in the tile
            for (size_t t = 0; t < tiles.tiles.size(); ++t) {
                const int32_t half = int32_t(1) << (tiles.tiles[t].log2Size - 1);
                bool edge = false;
                const auto probe = [&](const openvdb::Coord& at, ValueT& v) { return around.activeTile(at, v); };
                store(tileNormals_.tiles, t, normalAt(probe, openvdb::Coord(tiles.tiles[t].x + half, tiles.tiles[t].y + half, tiles.tiles[t].z + half), edge));
                oneSided_ += edge ? 1 : 0;
            }
            oneSided_ += grid.bandEdges_;
        }
        uint64_t oneSided() const { return oneSided_; }

        const GridRecord& header() const override { return header_; }
        LayerSummary summary(Layer layer) override {
            if (layer == Layer::Inactive) return {};
            LayerSummary s = grid_.summary_[0];
            s.mixed = false;  // the grid's values, not the normals
            s.uniformValue.clear();
            return s;
        }
        std::vector<CubeLoad> cubes(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2) override {
            return layer == Layer::Active ? grid_.cubes(layer, origin, log2) : std::vector<CubeLoad>{};
        }
        void largeTiles(Layer layer, unsigned log2, GridTopology& tiles, LayerValues& values) override {
            if (layer == Layer::Active) selectLargeTiles(grid_.tiles_[0], tileNormals_, sizeof(detail::NormalVector), log2, tiles, values);
            else tiles = {}, values = {};
        }
        void beginPass(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2, bool withValues) override {
            index_ = layer == Layer::Active ? grid_.cubeIndex(layer, origin, log2) : CubeIndexMap{};
            withValues_ = withValues;
        }
        // The cube's active bricks and tiles in the grid's own order
        // (VdbGridCubes::read), each voxel's value its normal.
        void read(const CubeCell& cell, GridTopology& topology, LayerValues& values) override {
            topology = {};
            values = {};
            const auto it = index_.find(cell);
            if (it == index_.end()) return;
            Neighbourhood around(grid_);
            for (const auto& [leafIndex, bricks] : it->second.leaves) around.load(leafIndex, withValues_, withValues_ && grid_.normalKind_ == NormalsOf::Gradient);
            std::vector<uint64_t> first{0};
            for (const auto& [leafIndex, bricks] : it->second.leaves) {
                const LeafInfo& leaf = grid_.leaves_[leafIndex];
                for (unsigned b = 0; b < 8; ++b) {
                    if (!((bricks >> b) & 1u)) continue;
                    const openvdb::Coord c = detail::brickCorner(leaf.origin, b);
                    const uint64_t m = around.brickMask(leaf.origin, b);
                    topology.bricks.push_back({c.x(), c.y(), c.z(), m});
                    first.push_back(first.back() + uint64_t(std::popcount(m)));
                }
            }
            if (withValues_) {
                values.bricks.resize(first.back() * sizeof(detail::NormalVector));
                std::vector<size_t> firstBrick{0};  // each leaf's first brick in `topology`
                for (const auto& [leafIndex, bricks] : it->second.leaves) firstBrick.push_back(firstBrick.back() + size_t(std::popcount(bricks)));
                tbb::parallel_for(tbb::blocked_range<size_t>(0, it->second.leaves.size(), 4), [&](const auto& range) {
                    auto block = std::make_unique<typename Neighbourhood::Block>();
                    for (size_t l = range.begin(); l != range.end(); ++l) {
                        const openvdb::Coord origin = grid_.leaves_[it->second.leaves[l].first].origin;
                        around.fill(origin, *block, grid_.normalKind_ == NormalsOf::Gradient);
                        const auto probe = [&](const openvdb::Coord& at, ValueT& v) {
                            const size_t i = detail::haloIndex(at.x() - origin.x(), at.y() - origin.y(), at.z() - origin.z());
                            v = block->value[i];
                            return block->on[i] != 0;
                        };
                        for (size_t i = firstBrick[l]; i != firstBrick[l + 1]; ++i) {
                            const Brick& brick = topology.bricks[i];
                            uint64_t out = first[i];
                            for (uint64_t bits = brick.mask; bits; bits &= bits - 1, ++out) {
                                const int bit = std::countr_zero(bits);
                                bool edge = false;
                                store(values.bricks, out, normalAt(probe, openvdb::Coord(brick.x + (bit & 3), brick.y + ((bit >> 2) & 3), brick.z + (bit >> 4)), edge));
                            }
                        }
                    }
                });
            }
            for (size_t t : it->second.tiles) {
                topology.tiles.push_back(grid_.tiles_[0].tiles[t]);
                if (withValues_) values.tiles.insert(values.tiles.end(), tileNormals_.tiles.begin() + long(t * sizeof(detail::NormalVector)),
                                                     tileNormals_.tiles.begin() + long((t + 1) * sizeof(detail::NormalVector)));
            }
            index_.erase(it);
        }
        void endPass() override { index_.clear(); }

    private:
        static void store(std::vector<uint8_t>& out, size_t index, const detail::NormalVector& v) {
            std::memcpy(&out[index * sizeof(v)], v.data(), sizeof(v));
        }
        // `probe(coord, ValueT&)` -> bool: OpenVDB's probeValue.
        template <typename Probe>
        detail::NormalVector normalAt(Probe&& probe, const openvdb::Coord& c, bool& edge) const {
            if constexpr (std::is_same_v<ValueT, float> || std::is_same_v<ValueT, double>) {
                if (grid_.normalKind_ == NormalsOf::Gradient) return detail::gradientNormalAt<ValueT>(probe, *grid_.map_, c, edge);
            } else if constexpr (std::is_same_v<ValueT, openvdb::Vec3s> || std::is_same_v<ValueT, openvdb::Vec3d> || std::is_same_v<ValueT, openvdb::Vec3i>) {
                ValueT v{};
                probe(c, v);
                return detail::vectorNormal(v);
            }
            return {0.f, 0.f, 0.f};
        }
        VdbGridCubes& grid_;
        GridRecord header_;
        LayerValues tileNormals_;
        uint64_t oneSided_ = 0;
        CubeIndexMap index_;
        bool withValues_ = false;
    };

    // Finds leaves and active tiles by position (for the normals).
    void indexNeighbours() {
        for (size_t i = 0; i < leaves_.size(); ++i) leafAt_.emplace(leaves_[i].origin, i);
        const GridTopology& tiles = tiles_[0];
        for (size_t t = 0; t < tiles.tiles.size(); ++t) {
            const Tile& tile = tiles.tiles[t];
            auto level = std::find_if(activeTileAt_.begin(), activeTileAt_.end(), [&](const auto& l) { return l.first == tile.log2Size; });
            if (level == activeTileAt_.end()) level = activeTileAt_.insert(activeTileAt_.end(), {tile.log2Size, {}});
            level->second.emplace(openvdb::Coord(tile.x, tile.y, tile.z), t);
        }
    }

    void summarise(GridT& grid) {
        TreeT& tree = grid.tree();
        const ValueT background = tree.background();
        summary_[0].voxels = tree.activeVoxelCount();
        // Tiles above the leaves: active ones, and inactive ones whose value
        // is not the background.
        typename TreeT::ValueAllCIter it = tree.cbeginValueAll();
        it.setMaxDepth(TreeT::ValueAllCIter::LEAF_DEPTH - 1);
        for (; it; ++it) {
            if (!it.isTileValue()) continue;
            const openvdb::CoordBBox box = it.getBoundingBox();
            const unsigned log2 = unsigned(std::countr_zero(unsigned(box.dim().x())));
            const Tile tile{box.min().x(), box.min().y(), box.min().z(), uint8_t(log2)};
            if (it.isValueOn()) {
                tiles_[0].tiles.push_back(tile);
                if constexpr (hasValues) detail::appendValue(tileValues_[0].tiles, *it);
            } else if constexpr (hasValues) {
                if (!detail::sameBits(ValueT(*it), background)) {
                    tiles_[1].tiles.push_back(tile);
                    detail::appendValue(tileValues_[1].tiles, *it);
                }
            }
        }
        std::vector<LeafT*> leaves;
        leaves.reserve(tree.leafCount());
        for (auto it = tree.beginLeaf(); it; ++it) leaves.push_back(it.getLeaf());
        leaves_.resize(leaves.size());
        std::vector<uint64_t> inactiveVoxels(leaves.size(), 0);
        // Whether the inactive values are OpenVDB's signed flood fill of the
        // active ones (SignedFill.h), leaf by leaf in the pass below, the tiles after.
        constexpr bool kFillable = hasValues && (std::is_same_v<ValueT, float> || std::is_same_v<ValueT, double>);
        bool fillable = false;
        if constexpr (kFillable) fillable = background > ValueT(0) && std::isfinite(double(background)) && tiles_[0].tiles.empty();
        std::vector<uint8_t> leafFill(fillable ? leaves.size() : 0);  // bit 0: the leaf is its fill; bits 1, 2: its first and last values negative
        // Chunk by chunk: each leaf's bricks of both layers, with values,
        // into the scratch file; then the chunk's leaves (and the file pages
        // their buffers were read from) are dropped.
        std::vector<std::vector<uint8_t>> records(std::min(leaves.size(), kLeafChunk));
        std::vector<uint32_t> activeEnds(records.size());
        std::vector<uint8_t> sameValues(records.size());  // per leaf, bit l: layer l's values all have the same bits
        for (size_t begin = 0; begin < leaves.size(); begin += kLeafChunk) {
            const size_t end = std::min(leaves.size(), begin + kLeafChunk);
            tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, 64), [&](const auto& r) {
                for (size_t i = r.begin(); i != r.end(); ++i) {
                    LeafInfo& info = leaves_[i];
                    info.origin = leaves[i]->origin();
                    info.occupancy[0] = info.occupancy[1] = 0;
                    std::vector<uint8_t>& record = records[i - begin];
                    record.clear();
                    uint64_t masks[2][8];
                    std::vector<uint8_t> valuesOf[2];
                    int count[2] = {0, 0};
                    for (unsigned b = 0; b < 8; ++b)
                        for (unsigned l = 0; l < 2; ++l) {
                            const uint64_t m = detail::leafBrick<LeafT, hasValues>(*leaves[i], b, Layer(l), background, &valuesOf[l]);
                            if (!m) continue;
                            info.occupancy[l] |= uint8_t(1u << b);
                            masks[l][count[l]++] = m;
                            if (l == 1) inactiveVoxels[i] += uint64_t(std::popcount(m));
                        }
                    for (unsigned l = 0; l < 2; ++l) {
                        const auto* p = reinterpret_cast<const uint8_t*>(masks[l]);
                        record.insert(record.end(), p, p + size_t(count[l]) * sizeof(uint64_t));
                    }
                    if constexpr (kFillable)
                        if (fillable) leafFill[i] = detail::leafSignedFill(*leaves[i], background);
                    sameValues[i - begin] = 0;
                    for (unsigned l = 0; l < 2; ++l) {
                        if (detail::allSameValue(valuesOf[l], valueSize(header_.valueType))) sameValues[i - begin] |= uint8_t(1u << l);
                        record.insert(record.end(), valuesOf[l].begin(), valuesOf[l].end());
                        if (l == 0) activeEnds[i - begin] = uint32_t(record.size());
                    }
                }
            });
            for (size_t i = begin; i < end; ++i) {
                leaves_[i].recordSize = uint32_t(records[i - begin].size());
                leaves_[i].activeEnd = activeEnds[i - begin];
                if constexpr (hasValues) noteLeafValues(records[i - begin], leaves_[i], sameValues[i - begin]);
                leaves_[i].recordOffset = scratch_->append(records[i - begin].data(), records[i - begin].size());
                if constexpr (hasValues) tree.addTile(1, leaves_[i].origin, background, false);
            }
            if constexpr (hasValues) releaseMappedPages(path_);
        }
        for (int l = 0; l < 2; ++l) {
            LayerSummary& s = summary_[l];
            s.noteValues(tileValues_[l].tiles, valueSize(header_.valueType));
            for (const LeafInfo& leaf : leaves_)
                for (uint8_t bits = leaf.occupancy[l]; bits; bits &= uint8_t(bits - 1)) {
                    const openvdb::Coord c = detail::brickCorner(leaf.origin, unsigned(std::countr_zero(bits)));
                    s.extend(c.x(), c.y(), c.z(), 4);
                    ++s.bricks;
                }
            for (const Tile& t : tiles_[l].tiles) {
                s.extend(t.x, t.y, t.z, int64_t(1) << t.log2Size);
                s.largestTileLog2 = std::max<unsigned>(s.largestTileLog2, t.log2Size);
            }
            s.tiles = tiles_[l].tiles.size();
        }
        if constexpr (kFillable)
            if (fillable) signedFill_ = tilesAreFill(leaves, leafFill, background);
        // As GridTopology::activeVoxelCount counts them.
        GridTopology inactive;
        inactive.tiles = tiles_[1].tiles;
        summary_[1].voxels = inactive.activeVoxelCount();
        for (uint64_t n : inactiveVoxels) summary_[1].voxels += n;
    }

    // Whether every leaf is its fill and the inactive tiles off the
    // background are exactly the inside tiles the fill puts above them.
    bool tilesAreFill(const std::vector<LeafT*>& leaves, const std::vector<uint8_t>& leafFill, ValueT background) const {
        SignedFillTree tree;
        for (size_t i = 0; i < leaves.size(); ++i) {
            if (!(leafFill[i] & 1)) return false;
            const openvdb::Coord o = leaves_[i].origin;
            tree.addLeaf({o.x(), o.y(), o.z()}, {{}, bool(leafFill[i] & 2), bool(leafFill[i] & 4)});
        }
        const std::vector<Tile> want = tree.insideTiles();
        const GridTopology& have = tiles_[1];
        if (want.size() != have.tiles.size()) return false;
        const ValueT inside = -background;
        std::set<std::tuple<int32_t, int32_t, int32_t, uint8_t>> wanted;
        for (const Tile& t : want) wanted.insert({t.x, t.y, t.z, t.log2Size});
        for (size_t t = 0; t < have.tiles.size(); ++t) {
            const Tile& tile = have.tiles[t];
            if (!wanted.contains({tile.x, tile.y, tile.z, tile.log2Size})) return false;
            if (!detail::sameBits(detail::valueFromBytes<ValueT>(&tileValues_[1].tiles[t * sizeof(ValueT)]), inside)) return false;
        }
        return true;
    }

    std::string path_, uniqueName_;
    GridRecord header_;
    bool signedFill_ = false;
    std::vector<LeafInfo> leaves_;
    GridTopology tiles_[2];
    LayerValues tileValues_[2];
    LayerSummary summary_[2];
    std::shared_ptr<ScratchFile> scratch_;  // shared by the file's grids
    // The current pass.
    Layer layer_ = Layer::Active;
    bool withValues_ = false;
    CubeIndexMap index_;
    // --normals
    NormalsOf normalKind_ = NormalsOf::None;
    openvdb::math::MapBase::ConstPtr map_;  // the grid's transform
    uint64_t bandEdges_ = 0;
    std::unordered_map<openvdb::Coord, size_t, CoordHash> leafAt_;
    std::vector<std::pair<unsigned, std::unordered_map<openvdb::Coord, size_t, CoordHash>>> activeTileAt_;  // per tile size
    std::unique_ptr<NormalCubes> normalCubes_;
};

} // namespace

bool canReadVdbByCubes(const std::string& path) {
    try {
        return detail::checkVdbFileLayout(path).hasGridOffsets;
    } catch (const Error&) {
        return false;
    }
}

VdbCubeInput openVdbCubes(const std::string& path, const ImportOptions& options, const std::string& scratchNear, uint64_t scratchInMemory) {
    if (options.normals && options.topologyOnly) throw Error(path + ": --normals with --topology-only needs the whole grid in memory");
    const detail::VdbFileIndex index = detail::indexVdbFile(path);
    const std::string near = scratchNear.empty() ? (std::filesystem::temp_directory_path() / "vdbdag").string() : scratchNear;
    std::shared_ptr<ScratchFile> scratch;  // created with the first grid
    VdbCubeInput input;
    input.fileMetadata = detail::serializeMetadata(*index.metadata);
    // --grid names the file lacks: refused before any grid is read.
    std::vector<std::string> found;
    for (const std::string& unique : index.uniqueNames) found.push_back(openvdb::io::GridDescriptor::stripSuffix(openvdb::io::GridDescriptor::stringAsUniqueName(unique)));
    for (const std::string& wanted : options.onlyGrids)
        if (std::find(found.begin(), found.end(), wanted) == found.end()) {
            std::string names;
            for (const auto& n : found) names += (names.empty() ? "'" : ", '") + n + "'";
            throw Error(path + ": no grid named '" + wanted + "' (the file has " + (names.empty() ? "no grids" : names) + ")");
        }
    bool anyNormals = false;
    for (size_t i = 0; i < index.uniqueNames.size(); ++i) {
        openvdb::GridBase::Ptr base = detail::readGridDelayed(path, index.uniqueNames[i]);
        detail::checkGridAgainstFile(path, i, *base);
        if (!options.onlyGrids.empty() && std::find(options.onlyGrids.begin(), options.onlyGrids.end(), base->getName()) == options.onlyGrids.end())
            continue;
        GridRecord header;
        header.name = base->getName();
        header.gridClass = openvdb::GridBase::gridClassToString(base->getGridClass());
        header.indexToWorld = detail::indexToWorldOf(*base);
        header.vdbDescriptor = detail::descriptorOf(*base);
        header.rescale = detail::rescaleOf(*base);
        const bool supported = detail::dispatchGridType(*base, [&](const auto& typed, ValueType type) {
            const NormalsOf normals = detail::normalsOf(typed, options, path);
            anyNormals = anyNormals || normals != NormalsOf::None;
            if (!scratch) scratch = std::make_shared<ScratchFile>(near, scratchInMemory);
            using GridT = std::decay_t<decltype(typed)>;
            constexpr bool typeHasValues = !std::is_same_v<typename GridT::TreeType::LeafNodeType::BuildType, openvdb::ValueMask>;
            typename GridT::Ptr grid = openvdb::gridPtrCast<GridT>(base);
            base.reset();
            if (options.topologyOnly || !typeHasValues) {
                header.valueType = ValueType::Mask;
                input.grids.push_back(std::make_unique<VdbGridCubes<GridT, false>>(path, index.uniqueNames[i], std::move(header), std::move(grid), scratch));
            } else {
                header.valueType = type;
                detail::appendValue(header.background, grid->tree().background());
                input.grids.push_back(
                    std::make_unique<VdbGridCubes<GridT, typeHasValues>>(path, index.uniqueNames[i], std::move(header), std::move(grid), scratch, normals));
            }
        });
        if (!supported) {
            const std::string message = "grid " + std::to_string(i) + " '" + base->getName() + "' has type '" + base->type() + "'" +
                                        detail::typeHint(*base) + ", which vdbdag does not convert";
            if (!options.skipUnsupported) throw Error(path + ": " + message + " (use --skip-unsupported to convert the other grids)");
            input.warnings.push_back(path + ": skipped " + message);
        }
    }
    if (options.normals) detail::requireSomeNormals(anyNormals, options, path);
    return input;
}

} // namespace vdbdag::bridge
