// A scalar dense scan as a CubeSource (DenseImport.h, cubesNear): the
// import pass wrote its stored samples to a scratch file; a cube read
// fetches the cube's rows of samples back, four slices at a time, and cuts
// them into bricks with the import's own rule (detail/DenseBricks.h), so
// the bricks and values are those of the in-memory import. Only the active
// layer exists (a scan has no inactive voxels: removed samples are the
// background); its tiles are the solid 8^3 blocks (SolidBlocks.h).
#include <algorithm>
#include <cstring>

#include "src/util/Error.h"
#include "vdb_bridge/detail/DenseBricks.h"

namespace vdbdag::bridge::detail {
namespace {

template <typename S, typename V>
class DenseCubes final : public CubeSource {
public:
    DenseCubes(const DenseVolume& v, const SampleRule<S, V>& rule, DenseCubeScratch scratch, const GridRecord& header)
        : rule_(rule), scratch_(std::move(scratch)), dims_(v.dims), header_(headerOf(header)) {}
    const GridRecord& header() const override { return header_; }
    LayerSummary summary(Layer layer) override { return layer == Layer::Active ? scratch_.summary : LayerSummary{}; }

    std::vector<CubeLoad> cubes(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2) override {
        std::vector<CubeLoad> out;
        if (layer != Layer::Active || scratch_.summary.empty()) return out;
        // Counts per cell, over the cells of the kept bricks' bounding box.
        const LayerSummary& box = scratch_.summary;
        auto cellOf = [&](int64_t c, int a) { return uint64_t(c - origin[size_t(a)]) >> log2; };
        for (int a = 0; a < 3; ++a)
            if (origin[size_t(a)] > box.min[size_t(a)]) throw Error("internal error: cube origin past the scan's first brick");
        const uint64_t x0 = cellOf(box.min[0], 0), y0 = cellOf(box.min[1], 1), z0 = cellOf(box.min[2], 2);
        const uint64_t cx = cellOf(box.max[0], 0) + 1, cy = cellOf(box.max[1], 1) + 1, cz = cellOf(box.max[2], 2) + 1;
        std::vector<uint64_t> counts(size_t((cx - x0) * (cy - y0) * (cz - z0)), 0);
        for (int64_t slab = 0; slab < scratch_.slabs; ++slab)
            for (int64_t row = 0; row < scratch_.rows; ++row)
                for (int64_t col = 0; col < scratch_.cols; ++col)
                    if (scratch_.has(col, row, slab))
                        ++counts[size_t(((cellOf(slab * 4, 2) - z0) * (cy - y0) + cellOf(row * 4, 1) - y0) * (cx - x0) + cellOf(col * 4, 0) - x0)];
        for (uint64_t z = z0; z < cz; ++z)
            for (uint64_t y = y0; y < cy; ++y)
                for (uint64_t x = x0; x < cx; ++x)
                    if (const uint64_t n = counts[size_t(((z - z0) * (cy - y0) + y - y0) * (cx - x0) + x - x0)])
                        out.push_back({{uint32_t(x), uint32_t(y), uint32_t(z)}, n});
        return out;
    }

    void largeTiles(Layer, unsigned, GridTopology& tiles, LayerValues& values) override {
        tiles = {};
        values = {};
    }

    void beginPass(Layer layer, const std::array<int64_t, 3>& origin, unsigned log2, bool withValues) override {
        layer_ = layer;
        origin_ = origin;
        log2_ = log2;
        withValues_ = withValues;
    }

    void read(const CubeCell& cell, GridTopology& topology, LayerValues& values) override {
        topology = {};
        values = {};
        if (layer_ != Layer::Active) return;
        const int64_t size = int64_t(1) << log2_;
        const int64_t c[3] = {int64_t(cell.x), int64_t(cell.y), int64_t(cell.z)};
        int64_t lo[3], hi[3];  // the cube's samples inside the scan
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::max<int64_t>(0, origin_[size_t(a)] + c[a] * size);
            hi[a] = std::min<int64_t>(dims_[size_t(a)], origin_[size_t(a)] + (c[a] + 1) * size);
            if (lo[a] >= hi[a]) return;
        }
        const int64_t nx = dims_[0], ny = dims_[1];
        const int64_t rx = hi[0] - lo[0], ry = hi[1] - lo[1];
        std::vector<S> slab(size_t(rx * ry * 4));
        std::vector<V> kept;
        PassStats ignored;
        for (int64_t z = lo[2]; z < hi[2]; z += 4) {  // lo is 4-aligned: the origin is
            const int64_t nz = std::min<int64_t>(4, dims_[2] - z);
            bool any = false;
            for (int64_t by = lo[1] / 4; by * 4 < hi[1] && !any; ++by)
                for (int64_t bx = lo[0] / 4; bx * 4 < hi[0] && !any; ++bx) any = scratch_.has(bx, by, z / 4);
            if (!any) continue;
            if (withValues_ || rule_.th.any() || !rule_.missingSlices.empty()) {  // the masks depend on the samples
                for (int64_t k = 0; k < nz; ++k)
                    for (int64_t y = lo[1]; y < hi[1]; ++y)
                        scratch_.file->readInto(uint64_t(((z + k) * ny + y) * nx + lo[0]) * sizeof(S), size_t(rx) * sizeof(S),
                                                slab.data() + size_t((k * ry + (y - lo[1])) * rx));
            }
            for (int64_t by = lo[1] / 4; by * 4 < hi[1]; ++by)
                for (int64_t bx = lo[0] / 4; bx * 4 < hi[0]; ++bx) {
                    if (!scratch_.has(bx, by, z / 4) || scratch_.blocks.covers(bx * 4, by * 4, z)) continue;
                    const uint64_t mask = cutBrick(rule_, slab.data() + size_t((by * 4 - lo[1]) * rx + (bx * 4 - lo[0])), size_t(rx), size_t(rx * ry),
                                                   std::min<int64_t>(4, nx - bx * 4), std::min<int64_t>(4, ny - by * 4), nz, z, ignored, kept);
                    topology.bricks.push_back({int32_t(bx * 4), int32_t(by * 4), int32_t(z), mask});
                }
        }
        if (withValues_) {
            values.bricks.resize(kept.size() * sizeof(V));
            std::memcpy(values.bricks.data(), kept.data(), values.bricks.size());
        }
        // The solid blocks whose corner is in the cube, as tiles; the
        // encoder's origin is a multiple of the largest tile's size (8), so
        // each lies wholly in one cube.
        const SolidBlocks& blocks = scratch_.blocks;
        if (blocks.count == 0) return;
        constexpr int64_t kSize = int64_t(1) << kSolidBlockLog2;
        int64_t b0[3], b1[3];
        for (int a = 0; a < 3; ++a) {
            const int64_t start = origin_[size_t(a)] + c[a] * size;
            b0[a] = (std::max<int64_t>(0, start) + kSize - 1) >> kSolidBlockLog2;
            b1[a] = (hi[a] + kSize - 1) >> kSolidBlockLog2;  // blocks past the scan are never solid
            if ((start & (kSize - 1)) != 0)
                throw Error("internal error: a cube at " + std::to_string(start) + " would cut a solid block (the cube origin is not a multiple of 8)");
        }
        for (int64_t z = b0[2]; z < b1[2]; ++z)
            for (int64_t y = b0[1]; y < b1[1]; ++y)
                for (int64_t x = b0[0]; x < b1[0]; ++x)
                    if (blocks.covers(x * kSize, y * kSize, z * kSize)) {
                        topology.tiles.push_back(solidBlockTile(x, y, z));
                        if (withValues_) values.tiles.insert(values.tiles.end(), blocks.valueOf(x, y, z), blocks.valueOf(x, y, z) + sizeof(V));
                    }
    }

    void endPass() override {}

private:
    SampleRule<S, V> rule_;
    DenseCubeScratch scratch_;
    std::array<int64_t, 3> dims_;
    GridRecord header_;
    Layer layer_ = Layer::Active;
    std::array<int64_t, 3> origin_{0, 0, 0};
    unsigned log2_ = 2;
    bool withValues_ = false;
};

} // namespace

template <typename S, typename V>
std::unique_ptr<CubeSource> makeDenseCubes(const DenseVolume& v, const SampleRule<S, V>& rule, DenseCubeScratch scratch, const GridRecord& header) {
    return std::make_unique<DenseCubes<S, V>>(v, rule, std::move(scratch), header);
}

#define VDBDAG_DENSE_CUBES(S, V) \
    template std::unique_ptr<CubeSource> makeDenseCubes<S, V>(const DenseVolume&, const SampleRule<S, V>&, DenseCubeScratch, const GridRecord&);
VDBDAG_DENSE_CUBES(uint8_t, int32_t)
VDBDAG_DENSE_CUBES(int8_t, int32_t)
VDBDAG_DENSE_CUBES(uint16_t, int32_t)
VDBDAG_DENSE_CUBES(int16_t, int32_t)
VDBDAG_DENSE_CUBES(int32_t, int32_t)
VDBDAG_DENSE_CUBES(uint32_t, int64_t)
VDBDAG_DENSE_CUBES(float, float)
VDBDAG_DENSE_CUBES(double, double)
VDBDAG_DENSE_CUBES(uint8_t, float)
VDBDAG_DENSE_CUBES(int8_t, float)
VDBDAG_DENSE_CUBES(uint16_t, float)
VDBDAG_DENSE_CUBES(int16_t, float)
VDBDAG_DENSE_CUBES(uint32_t, double)
VDBDAG_DENSE_CUBES(int32_t, double)
#undef VDBDAG_DENSE_CUBES

} // namespace vdbdag::bridge::detail
