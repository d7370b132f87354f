// RecordCubes (CubeSource.h): a grid in memory, sliced into cubes.
#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "src/volume/SignedFill.h"
#include "src/util/Error.h"
#include "src/volume/CubeSource.h"

namespace vdbdag {
namespace {

struct CellLess {
    bool operator()(const CubeCell& a, const CubeCell& b) const { return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x); }
};

class RecordCubes final : public CubeSource {
public:
    explicit RecordCubes(const GridRecord& grid)
        : header_(headerOf(grid)), active_(grid.topology), inactive_(grid.inactiveTopology), activeValues_(grid.values),
          inactiveValues_(grid.inactiveValues), valueSize_(valueSize(grid.valueType)) {
        if (grid.normals) normals_ = std::make_unique<Normals>(grid);
    }
    // The normal channel of `grid` (which has normals): its active voxels,
    // each with its exact normal as a vec3s value; no inactive layer.
    struct NormalsOf {
        const GridRecord& grid;
    };
    explicit RecordCubes(NormalsOf n)
        : header_(headerOf(n.grid)), active_(n.grid.topology), inactive_(empty_), activeValues_(n.grid.normals->vectors), inactiveValues_(noValues_),
          valueSize_(sizeof(std::array<float, 3>)) {
        header_.valueType = ValueType::Vec3S;
        header_.background.assign(valueSize_, 0);
    }
    // Its references may point at its own empty layer: never copied or moved.
    RecordCubes(const RecordCubes&) = delete;
    RecordCubes& operator=(const RecordCubes&) = delete;
    const GridRecord& header() const override { return header_; }
    std::optional<NormalSource> normals() override {
        if (!normals_) return NormalSource{};  // a grid in memory without normals: none to store
        return NormalSource{normals_->cubes.get(), normals_->fromNormalGrid, normals_->oneSided};
    }

    bool inactiveIsSignedFill() override {
        if (inactive_.empty()) return false;
        const std::optional<InactiveLayer> fill = signedFillInactive(active_, activeValues_, header_.valueType, header_.background);
        return fill && sameInactiveLayer(fill->topology, fill->values, inactive_, inactiveValues_, header_.valueType);
    }

    LayerSummary summary(Layer layer) override {
        const GridTopology& t = topology(layer);
        LayerSummary s;
        s.bricks = t.bricks.size();
        s.tiles = t.tiles.size();
        s.voxels = t.activeVoxelCount();
        for (const Brick& b : t.bricks) s.extend(b.x, b.y, b.z, 4);
        for (const Tile& tile : t.tiles) {
            s.extend(tile.x, tile.y, tile.z, int64_t(1) << tile.log2Size);
            s.largestTileLog2 = std::max<unsigned>(s.largestTileLog2, tile.log2Size);
        }
        return s;
    }

    std::vector<CubeLoad> cubes(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2) override {
        std::map<CubeCell, uint64_t, CellLess> counts;
        const GridTopology& t = topology(layer);
        for (const Brick& b : t.bricks) ++counts[cellOf(origin, log2, b.x, b.y, b.z)];
        for (const Tile& tile : t.tiles)
            if (tile.log2Size <= log2) ++counts[cellOf(origin, log2, tile.x, tile.y, tile.z)];
        std::vector<CubeLoad> out;
        for (const auto& [cell, n] : counts) out.push_back({cell, n});
        return out;
    }

    void largeTiles(Layer layer, unsigned log2, GridTopology& tiles, LayerValues& values) override {
        selectLargeTiles(topology(layer), layerValues(layer), valueSize_, log2, tiles, values);
    }

    void beginPass(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2, bool withValues) override {
        layer_ = layer;
        withValues_ = withValues;
        const GridTopology& t = topology(layer);
        index_.clear();
        uint64_t value = 0;
        for (size_t i = 0; i < t.bricks.size(); ++i) {
            const Brick& b = t.bricks[i];
            index_[cellOf(origin, log2, b.x, b.y, b.z)].bricks.push_back({i, value});
            value += uint64_t(std::popcount(b.mask));
        }
        for (size_t i = 0; i < t.tiles.size(); ++i)
            if (t.tiles[i].log2Size <= log2) index_[cellOf(origin, log2, t.tiles[i].x, t.tiles[i].y, t.tiles[i].z)].tiles.push_back(i);
    }

    void read(const CubeCell& cell, GridTopology& topology, LayerValues& values) override {
        topology = {};
        values = {};
        const auto it = index_.find(cell);
        if (it == index_.end()) return;
        const GridTopology& t = this->topology(layer_);
        const LayerValues& v = layerValues(layer_);
        const unsigned vs = withValues_ ? valueSize_ : 0;
        for (const auto& [brick, firstValue] : it->second.bricks) {
            topology.bricks.push_back(t.bricks[brick]);
            if (vs) {
                const size_t n = size_t(std::popcount(t.bricks[brick].mask)) * vs;
                values.bricks.insert(values.bricks.end(), v.bricks.begin() + long(firstValue * vs), v.bricks.begin() + long(firstValue * vs + n));
            }
        }
        for (size_t tile : it->second.tiles) {
            topology.tiles.push_back(t.tiles[tile]);
            if (vs) values.tiles.insert(values.tiles.end(), v.tiles.begin() + long(tile * vs), v.tiles.begin() + long((tile + 1) * vs));
        }
    }

    void endPass() override { index_.clear(); }

private:
    static CubeCell cellOf(const std::array<int64_t, 3>& origin, unsigned log2, int64_t x, int64_t y, int64_t z) {
        return {uint32_t(uint64_t(x - origin[0]) >> log2), uint32_t(uint64_t(y - origin[1]) >> log2), uint32_t(uint64_t(z - origin[2]) >> log2)};
    }
    const GridTopology& topology(Layer layer) const { return layer == Layer::Active ? active_ : inactive_; }
    const LayerValues& layerValues(Layer layer) const { return layer == Layer::Active ? activeValues_ : inactiveValues_; }

    struct CubeIndex {
        std::vector<std::pair<size_t, uint64_t>> bricks;  // (brick, its first value)
        std::vector<size_t> tiles;
    };
    struct Normals {
        explicit Normals(const GridRecord& grid)
            : cubes(std::make_unique<RecordCubes>(NormalsOf{grid})), fromNormalGrid(grid.normals->fromNormalGrid), oneSided(grid.normals->oneSided) {}
        std::unique_ptr<RecordCubes> cubes;
        bool fromNormalGrid;
        uint64_t oneSided;
    };
    GridRecord header_;
    const GridTopology empty_;
    const LayerValues noValues_;
    const GridTopology& active_;
    const GridTopology& inactive_;
    const LayerValues& activeValues_;
    const LayerValues& inactiveValues_;
    const unsigned valueSize_;
    std::unique_ptr<Normals> normals_;
    Layer layer_ = Layer::Active;
    bool withValues_ = false;
    std::map<CubeCell, CubeIndex, CellLess> index_;
};

} // namespace

std::unique_ptr<CubeSource> recordCubes(const GridRecord& grid) { return std::make_unique<RecordCubes>(grid); }

} // namespace vdbdag
