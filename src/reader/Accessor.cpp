// vdbdag::Accessor (include/vdbdag/vdbdag.h): a point lookup in the compact
// DAG. From the root (or the deepest node of the last walk that holds the
// voxel), each inner node's child is the spatial slot of the voxel's
// coordinate bits mapped through the node's accumulated mirror mask to its
// stored slot; the child pointer's own reflection composes with the mask
// and its attribute offset adds to the entry base (DESIGN.md invariant 2).
// A solid node holds one entry for its whole cube; in a 4^3 leaf the entry
// is the base plus the rank of the voxel's stored bit among the brick's set
// bits. The words are read by <vdbdag/dag_access.h>, the one parser of
// the compact DAG for C++ and GLSL. Above the walk, the brick cache
// (Accessor::BrickCache, docs/LIBRARY.md) holds whole 4^3 bricks of values
// for coherent lookups.
#include <vdbdag/vdbdag.h>
#include <vdbdag/dag_access.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <utility>

#include "src/encoding/CompactDag.h"
#include "src/reader/GridData.h"

namespace vdbdag {
namespace detail {

bool Layer::find(int64_t i, int64_t j, int64_t k, Accessor::Path& path, uint64_t& entry) const {
    const encoding::CompactDag& d = *dag;
    if (d.empty() || d.innerLevelCount() == 0 || d.log2Size > 62) return false;
    // Relative to the root's corner; below it wraps to a huge value, so one
    // unsigned comparison per axis tests the root cube.
    const uint64_t size = uint64_t(1) << d.log2Size;
    const std::array<uint64_t, 3> rel{uint64_t(i) - uint64_t(d.origin[0]), uint64_t(j) - uint64_t(d.origin[1]), uint64_t(k) - uint64_t(d.origin[2])};
    if (rel[0] >= size || rel[1] >= size || rel[2] >= size) return false;
    unsigned t = 0;
    if (path.depth == 0) {
        path.nodes[0] = {d.levelStart[0], 0, d.rootReflection};
    } else {
        // The highest coordinate bit in which this voxel and the last one
        // differ gives the deepest node of the last walk that holds both.
        const auto& key = path.key;
        const uint64_t diff = (rel[0] ^ uint64_t(key[0])) | (rel[1] ^ uint64_t(key[1])) | (rel[2] ^ uint64_t(key[2]));
        if (diff < 4 && path.leaf.valid) {  // the same 4^3 brick: no walk
            const Accessor::Path::Leaf& leaf = path.leaf;
            path.key = {int64_t(rel[0]), int64_t(rel[1]), int64_t(rel[2])};
            return access::dagLeafEntry(leaf.stored, rel[0], rel[1], rel[2], leaf.mirror, leaf.base, entry);
        }
        if (path.uniform.log2 < 64 && (diff >> path.uniform.log2) == 0) {  // the same solid or empty cube
            path.key = {int64_t(rel[0]), int64_t(rel[1]), int64_t(rel[2])};
            entry = path.uniform.entry;
            return path.uniform.found;
        }
        const unsigned shared = d.log2Size - unsigned(std::bit_width(diff));  // levels whose cube holds both
        t = std::min(path.depth - 1, shared);
    }
    path.leaf.valid = false;
    path.uniform.log2 = 64;
    path.key = {int64_t(rel[0]), int64_t(rel[1]), int64_t(rel[2])};
    for (;; ++t) {
        path.depth = t + 1;
        const Accessor::Path::Node& n = path.nodes[t];
        const uint16_t header = d.inner[n.pos];
        if (header == 0) {  // solid: one entry for the whole cube
            entry = n.base;
            path.uniform = {d.log2Size - t, true, entry};
            return true;
        }
        const unsigned half = d.log2Size - t - 1;  // log2 of a child's size
        unsigned mirror = n.mirror;
        uint64_t base = n.base, childOffset;
        if (!access::dagDescend(d.inner.data(), n.pos, header, rel[0], rel[1], rel[2], half, d.offsetWords[t], mirror, base, childOffset)) {
            path.uniform = {half, false, 0};  // an empty child: none of its cube
            return false;
        }
        if (t + 1 == d.innerLevelCount()) {  // the child is a 4^3 leaf
            const uint64_t stored = d.leaves[childOffset];
            path.leaf = {stored, base, mirror, true};
            return access::dagLeafEntry(stored, rel[0], rel[1], rel[2], mirror, base, entry);
        }
        if (t + 1 >= Accessor::Path::kMaxDepth) throw Error(what + ": the DAG is deeper than " + std::to_string(Accessor::Path::kMaxDepth) + " levels");
        path.nodes[t + 1] = {d.levelStart[t + 1] + childOffset, base, mirror};
    }
}

Layer::Brick Layer::brick(int64_t i, int64_t j, int64_t k, Accessor::Path& path) const {
    const encoding::CompactDag& d = *dag;
    Brick b;
    if (d.empty() || d.innerLevelCount() == 0 || d.log2Size > 62) return b;
    const uint64_t size = uint64_t(1) << d.log2Size;
    if (uint64_t(i) - uint64_t(d.origin[0]) >= size || uint64_t(j) - uint64_t(d.origin[1]) >= size || uint64_t(k) - uint64_t(d.origin[2]) >= size) return b;
    uint64_t entry = 0;
    const bool found = find(i, j, k, path, entry);
    // The walk ended in the brick's leaf, or in a solid or empty cube around it.
    if (path.leaf.valid) b = {Brick::kLeaf, path.leaf.base, path.leaf.stored, path.leaf.mirror};
    else if (found) b = {Brick::kUniform, entry, 0, 0};
    return b;
}

} // namespace detail

// The brick cache. A brick's 64 voxels take the background, then the
// inactive layer's values, then the active layer's (a voxel is in one
// layer at most). A leaf's stored bit of spatial voxel s under mirror mask
// m is s ^ x, where x flips the two bits of each mirrored axis (3 - c = c ^ 3
// for c in 0..3); its entries are consecutive in stored-bit order.
Accessor::Accessor(const detail::GridData* grid) : grid_(grid), valueSize_(grid->valueSize) {
    grid->load();  // the grid's DAGs, on its first walk
    for (const encoding::CompactDag* d : {&grid->grid.active.dag, &grid->grid.inactive.dag})
        for (const int64_t o : d->origin)
            if (o % 4 != 0) cache_.usable = false;  // not what the encoder writes (a multiple of the alignment, at least 4)
}

int64_t Accessor::brickSlot(int64_t i, int64_t j, int64_t k) {
    if (!cache_.usable) return -1;
    if (const int64_t found = filledSlot(i, j, k); found >= 0) return found;
    const int64_t bx = i >> 2, by = j >> 2, bz = k >> 2;
    const size_t s = BrickCache::slotOf(bx, by, bz);
    // The brick of the last miss again, or one next to it (a sweep), is
    // copied; a brick far from it (a scattered lookup) is not.
    const BrickCache::Key last = cache_.lastMiss;
    cache_.lastMiss = {bx, by, bz};
    const bool near = last.x != INT64_MIN && uint64_t(bx - last.x + 1) <= 2 && uint64_t(by - last.y + 1) <= 2 && uint64_t(bz - last.z + 1) <= 2;
    if (!near) return -1;
    fillSlot(s, bx, by, bz);
    return int64_t(s);
}

namespace {

// One layer's part of a brick (detail::Layer::brick) and, unless the grid
// is a mask, the values of its entries (a solid node's one, or a leaf's in
// stored-bit order).
struct BrickPart {
    detail::Layer::Brick brick;
    uint8_t values[64 * sizeof(Accessor::Path::value)];
};

// Writes a brick's 64 values (N bytes each; N = 0: none) into `dst`: the
// background, then each part's. Returns the active mask of the last part
// (the active layer). N known to the compiler for the value types' sizes:
// copying with libc's memmove per voxel was a quarter of a coherent sweep.
template <unsigned N>
uint64_t writeBrick(uint8_t* dst, const uint8_t* background, const BrickPart* parts, size_t partCount, unsigned vs) {
    const unsigned size = N ? N : vs;
    const auto copy = [&](uint8_t* to, const uint8_t* from) {
        if constexpr (N > 0) std::memcpy(to, from, N);
        else std::memcpy(to, from, size);
    };
    if (size > 0)
        for (unsigned v = 0; v < 64; ++v) copy(dst + v * size, background);
    uint64_t active = 0;
    for (size_t p = 0; p < partCount; ++p) {
        const detail::Layer::Brick& b = parts[p].brick;
        active = 0;
        if (b.kind == detail::Layer::Brick::kNone) continue;
        if (b.kind == detail::Layer::Brick::kUniform) {
            active = ~uint64_t(0);
            if (size > 0)
                for (unsigned v = 0; v < 64; ++v) copy(dst + v * size, parts[p].values);
            continue;
        }
        const unsigned flip = ((b.mirror & 1u) ? 3u : 0u) | ((b.mirror & 2u) ? 12u : 0u) | ((b.mirror & 4u) ? 48u : 0u);
        unsigned r = 0;
        for (uint64_t bits = b.stored; bits != 0; bits &= bits - 1, ++r) {
            const unsigned v = unsigned(std::countr_zero(bits)) ^ flip;
            active |= uint64_t(1) << v;
            if (size > 0) copy(dst + v * size, parts[p].values + r * size);
        }
    }
    return active;
}

} // namespace

void Accessor::fillSlot(size_t s, int64_t bx, int64_t by, int64_t bz) {
    const unsigned vs = valueSize_;
    if (cache_.filled.empty()) {
        cache_.active.resize(BrickCache::kSlots);
        cache_.values.resize(BrickCache::kSlots * 64 * vs);
        cache_.filled.resize(BrickCache::kSlots);
    }
    BrickPart parts[2];  // the inactive layer's, then the active one's (a voxel is in one layer at most)
    const std::array<std::pair<const detail::Layer*, Path*>, 2> layers{{{&grid_->inactive, &inactive_}, {&grid_->active, &active_}}};
    for (size_t p = 0; p < 2; ++p) {
        const auto [layer, path] = layers[p];
        const detail::Layer::Brick b = parts[p].brick = layer->brick(bx * 4, by * 4, bz * 4, *path);
        if (vs == 0 || b.kind == detail::Layer::Brick::kNone) continue;
        layer->values(b.entry, b.kind == detail::Layer::Brick::kUniform ? 1 : uint64_t(std::popcount(b.stored)), parts[p].values, path->paletteHint);
    }
    uint8_t* dst = cache_.values.data() + s * 64 * vs;
    const uint8_t* background = grid_->grid.record.background.data();
    uint64_t active = 0;
    switch (vs) {
    case 0: active = writeBrick<0>(dst, background, parts, 2, vs); break;
    case 1: active = writeBrick<1>(dst, background, parts, 2, vs); break;
    case 4: active = writeBrick<4>(dst, background, parts, 2, vs); break;
    case 8: active = writeBrick<8>(dst, background, parts, 2, vs); break;
    case 12: active = writeBrick<12>(dst, background, parts, 2, vs); break;
    case 24: active = writeBrick<24>(dst, background, parts, 2, vs); break;
    default: active = writeBrick<0>(dst, background, parts, 2, vs);
    }
    cache_.active[s] = active;
    cache_.filled[s] = {bx, by, bz};
}

bool Accessor::isActive(int64_t i, int64_t j, int64_t k) {
    // A brick of a grid with values is copied by a value's lookup only, so
    // that asking for active states decodes no values.
    const int64_t s = valueSize_ == 0 ? brickSlot(i, j, k) : filledSlot(i, j, k);
    if (s >= 0) return (cache_.active[size_t(s)] >> voxelInBrick(i, j, k)) & 1u;
    uint64_t entry = 0;
    return grid_->active.find(i, j, k, active_, entry);
}

void Accessor::valueBytes(int64_t i, int64_t j, int64_t k, void* out) {
    if (grid_->valueSize == 0) return;
    auto* bytes = static_cast<uint8_t*>(out);
    if (const int64_t s = brickSlot(i, j, k); s >= 0) {
        std::memcpy(bytes, cache_.values.data() + (size_t(s) * 64 + voxelInBrick(i, j, k)) * valueSize_, valueSize_);
        return;
    }
    uint64_t entry = 0;
    const auto read = [&](const detail::Layer& layer, Path& path) {
        if (entry != path.valueEntry) {
            layer.value(entry, path.value, path.paletteHint);
            path.valueEntry = entry;
        }
        std::memcpy(bytes, path.value, grid_->valueSize);
    };
    if (grid_->active.find(i, j, k, active_, entry)) {
        read(grid_->active, active_);
    } else if (grid_->inactive.find(i, j, k, inactive_, entry)) {
        read(grid_->inactive, inactive_);
    } else {
        std::memcpy(bytes, grid_->grid.record.background.data(), grid_->valueSize);
    }
}

std::array<uint64_t, 3> sampleDims(const IndexBBox& box, uint64_t stride) {
    if (stride == 0) throw Error("a box read every 0 voxels");
    if (box.empty()) return {0, 0, 0};
    std::array<uint64_t, 3> dims{};
    for (int a = 0; a < 3; ++a) dims[a] = (uint64_t(box.max[a]) - uint64_t(box.min[a])) / stride + 1;  // max >= min: no wrap
    return dims;
}

uint64_t sampleCount(const IndexBBox& box, uint64_t stride) {
    const std::array<uint64_t, 3> dims = sampleDims(box, stride);
    uint64_t count = 1;
    for (const uint64_t n : dims) {
        if (n != 0 && count > (uint64_t(1) << 62) / n)
            throw Error("a box of " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " + std::to_string(dims[2]) + " samples");
        count *= n;
    }
    return count;
}

namespace {
// Calls visit(i, j, k) at box.min + n * stride, i fastest.
template <typename Visit>
void forEachSample(const IndexBBox& box, uint64_t stride, Visit&& visit) {
    const std::array<uint64_t, 3> dims = sampleDims(box, stride);
    sampleCount(box, stride);  // refuses a count past 2^62
    for (uint64_t z = 0; z < dims[2]; ++z)
        for (uint64_t y = 0; y < dims[1]; ++y)
            for (uint64_t x = 0; x < dims[0]; ++x)
                visit(box.min[0] + int64_t(x * stride), box.min[1] + int64_t(y * stride), box.min[2] + int64_t(z * stride));
}
} // namespace

void Grid::sampleBox(const IndexBBox& box, uint64_t stride, void* out) const {
    auto* bytes = static_cast<uint8_t*>(out);
    Accessor a = accessor();
    const unsigned vs = data_->valueSize;
    if (vs == 0) return sampleActive(box, stride, bytes);
    forEachSample(box, stride, [&](int64_t i, int64_t j, int64_t k) {
        a.valueBytes(i, j, k, bytes);
        bytes += vs;
    });
}

void Grid::sampleActive(const IndexBBox& box, uint64_t stride, uint8_t* out) const {
    Accessor a = accessor();
    forEachSample(box, stride, [&](int64_t i, int64_t j, int64_t k) { *out++ = a.isActive(i, j, k) ? 1 : 0; });
}

// The DAG's instances in attribute order (encoding::visitInAttributeOrder),
// cut into subtrees of at most 2^7 voxels so that those outside the box are
// skipped whole.
void Grid::forEachActive(const IndexBBox& box, const ActiveVisitor& visit) const {
    data_->load();
    const encoding::CompactDag& d = data_->grid.active.dag;
    if (d.empty() || d.innerLevelCount() == 0 || d.log2Size > 62 || box.empty()) return;
    const detail::Layer& layer = data_->active;
    const bool mask = data_->valueSize == 0;
    uint8_t value[sizeof(Accessor::Path::value)] = {};
    size_t hint = 0;
    bool stopped = false;
    const auto overlaps = [&](int64_t x, int64_t y, int64_t z, unsigned log2) {
        const int64_t c[3] = {x, y, z};
        for (int a = 0; a < 3; ++a)
            if (c[a] > box.max[a] || c[a] + ((int64_t(1) << log2) - 1) < box.min[a]) return false;
        return true;
    };
    const auto emit = [&](const std::array<int64_t, 3>& corner, unsigned log2, uint64_t entry) {
        if (!mask) layer.value(entry, value, hint);
        stopped = !visit(corner, log2, mask ? nullptr : value);
    };
    const encoding::BrickInstanceVisitor brick = [&](const encoding::BrickInstance& b) {
        if (stopped || !overlaps(b.x, b.y, b.z, 2)) return;
        for (unsigned z = 0; z < 4 && !stopped; ++z)
            for (unsigned y = 0; y < 4 && !stopped; ++y)
                for (unsigned x = 0; x < 4 && !stopped; ++x) {
                    const unsigned bit = access::dagStoredBit(x, y, z, b.mirror);
                    if (((b.storedMask >> bit) & 1u) == 0) continue;
                    const std::array<int64_t, 3> at{b.x + int64_t(x), b.y + int64_t(y), b.z + int64_t(z)};
                    if (at[0] < box.min[0] || at[0] > box.max[0] || at[1] < box.min[1] || at[1] > box.max[1] || at[2] < box.min[2] || at[2] > box.max[2])
                        continue;
                    emit(at, 0, b.firstEntry + access::dagLeafRank(b.storedMask, bit));
                }
    };
    const encoding::SolidVisitor solid = [&](int64_t x, int64_t y, int64_t z, unsigned log2, uint64_t entry) {
        if (!stopped && overlaps(x, y, z, log2)) emit({x, y, z}, log2, entry);
    };
    for (const encoding::SubtreeInstance& s : encoding::subtreesInAttributeOrder(d, std::min<unsigned>(7, d.log2Size))) {
        if (stopped) return;
        if (!overlaps(s.x, s.y, s.z, s.log2Size)) continue;
        if (s.solid) solid(s.x, s.y, s.z, s.log2Size, s.firstEntry);
        else encoding::visitSubtreeInAttributeOrder(d, s, brick, solid);
    }
}

unsigned Accessor::valueSize() const { return grid_->valueSize; }
bool Accessor::maskGrid() const { return grid_->grid.record.valueType == ValueType::Mask; }

bool detail::valueTypeFits(const GridData* grid, int code, size_t size) noexcept {
    return code >= 0 ? code == int(grid->grid.record.valueType) : size == grid->valueSize;
}

void detail::refuseValueType(const GridData* grid, int code, size_t size) {
    const ValueType held = grid->grid.record.valueType;
    const std::string asked = code >= 0 ? std::string(valueTypeName(ValueType(code))) : "a " + std::to_string(size) + "-byte type";
    throw Error("grid '" + grid->grid.record.name + "': a value asked as " + asked + " of a " + valueTypeName(held) + " grid (" +
                std::to_string(grid->valueSize) + " bytes; use its own type)");
}

bool Accessor::valueBytesOrFailure(int64_t i, int64_t j, int64_t k, void* out) noexcept {
    try {
        valueBytes(i, j, k, out);
        return true;
    } catch (...) {
        failure_ = std::current_exception();
        return false;
    }
}

void Accessor::rethrowFailure() { std::rethrow_exception(std::exchange(failure_, nullptr)); }

} // namespace vdbdag
