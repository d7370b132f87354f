// See DagBounds.h.
#include "src/format/DagBounds.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>

#include "src/encoding/DagDescent.h"
#include "src/util/Error.h"

namespace vdbdag::format {
namespace {

// A node's box in its own frame (0 .. size-1 on each axis), unreflected.
struct LocalBox {
    std::array<int64_t, 3> lo{}, hi{};
    bool any = false;
    void merge(const LocalBox& o) {
        if (!o.any) return;
        for (int a = 0; a < 3; ++a) {
            lo[a] = any ? std::min(lo[a], o.lo[a]) : o.lo[a];
            hi[a] = any ? std::max(hi[a], o.hi[a]) : o.hi[a];
        }
        any = true;
    }
    // The same node reflected by `m` (node `size` wide), then moved by `at`.
    LocalBox placed(unsigned m, int64_t size, const std::array<int64_t, 3>& at) const {
        LocalBox out = *this;
        for (int a = 0; a < 3; ++a) {
            if ((m >> a) & 1u) {
                out.lo[a] = size - 1 - hi[a];
                out.hi[a] = size - 1 - lo[a];
            }
            out.lo[a] += at[a];
            out.hi[a] += at[a];
        }
        return out;
    }
};

// A 4^3 brick's box (bit x + 4y + 16z): per axis, the first and last of
// its four planes that hold a voxel.
LocalBox brickBox(uint64_t mask) {
    LocalBox b;
    if (!mask) return b;
    // The voxels of plane c on each axis: x = c (every fourth bit), y = c
    // (four runs of four), z = c (sixteen bits).
    static constexpr uint64_t kPlane[3] = {0x1111111111111111ull, 0x000F000F000F000Full, 0xFFFFull};
    static constexpr unsigned kStep[3] = {1, 4, 16};
    for (int a = 0; a < 3; ++a) {
        unsigned planes = 0;
        for (unsigned c = 0; c < 4; ++c) planes |= unsigned((mask & (kPlane[a] << (kStep[a] * c))) != 0) << c;
        b.lo[a] = std::countr_zero(planes);
        b.hi[a] = 31 - std::countl_zero(planes);
    }
    b.any = true;
    return b;
}

// One level's node boxes, indexed by the node's word offset in the level,
// in the narrowest unsigned type that holds the level's local coordinates
// (a node of 8 voxels needs 6 bytes, not 48): the level above the leaves
// has about one entry per 16-bit word of the whole DAG.
class LevelBoxes {
public:
    LevelBoxes(uint64_t words, int64_t nodeSize)
        : width_(nodeSize <= 256 ? 1 : nodeSize <= 65536 ? 2 : nodeSize <= (int64_t(1) << 32) ? 4 : 8), bytes_(size_t(words) * 6 * width_) {}
    LocalBox get(uint64_t at) const {
        LocalBox b;
        const uint8_t* p = bytes_.data() + at * 6 * width_;
        for (int a = 0; a < 3; ++a) {
            b.lo[a] = read(p + a * width_);
            b.hi[a] = read(p + (3 + a) * width_);
        }
        // Stored as lo = hi + 1 on x when empty (a node is never empty but
        // for the unset words between node starts).
        b.any = b.lo[0] <= b.hi[0];
        return b;
    }
    void set(uint64_t at, const LocalBox& b) {
        uint8_t* p = bytes_.data() + at * 6 * width_;
        for (int a = 0; a < 3; ++a) {
            write(p + a * width_, b.any ? b.lo[a] : (a == 0 ? 1 : 0));
            write(p + (3 + a) * width_, b.any ? b.hi[a] : 0);
        }
    }

private:
    int64_t read(const uint8_t* p) const {
        uint64_t v = 0;
        std::memcpy(&v, p, width_);  // little-endian low bytes
        return int64_t(v);
    }
    void write(uint8_t* p, int64_t v) const {
        const uint64_t u = uint64_t(v);
        std::memcpy(p, &u, width_);
    }
    unsigned width_;
    std::vector<uint8_t> bytes_;
};

} // namespace

std::optional<IndexBox> dagBounds(const encoding::CompactDag& dag) {
    if (dag.empty()) return std::nullopt;
    const size_t levels = dag.innerLevelCount();
    std::optional<LevelBoxes> below;
    LocalBox root;

    for (size_t i = levels; i-- > 0;) {
        const uint64_t begin = dag.levelStart[i], end = dag.levelEnd(i);
        const int64_t size = int64_t(1) << (dag.log2Size - i), half = size / 2;
        const bool toLeaves = i + 1 == levels;
        LevelBoxes here(end - begin, size);
        encoding::forEachNode(dag, i, [&](uint64_t pos, uint16_t header) {
            LocalBox box;
            if (header == 0) {  // solid node
                box = LocalBox{{0, 0, 0}, {size - 1, size - 1, size - 1}, true};
            } else {
                encoding::forEachStoredChild(dag, i, pos, [&](unsigned j, const encoding::ChildPointer& p) {
                    const std::array<int64_t, 3> at{(j & 1u) ? half : 0, (j & 2u) ? half : 0, (j & 4u) ? half : 0};
                    const LocalBox child = toLeaves ? brickBox(dag.leaves[p.offset]) : below->get(p.offset);
                    box.merge(child.placed(p.reflection, half, at));
                });
            }
            if (i > 0) here.set(pos - begin, box);
            else if (pos == 0) root = box;  // the root level holds one node, at word 0
        });
        below.emplace(std::move(here));
    }
    const LocalBox placed = root.placed(dag.rootReflection, int64_t(1) << dag.log2Size, dag.origin);
    if (!placed.any) return std::nullopt;
    return IndexBox{placed.lo, placed.hi};
}

} // namespace vdbdag::format
