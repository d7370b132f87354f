// See SignedFill.h. The loops below follow openvdb/tools/SignedFloodFill.h's
// SignedFloodFillOp statement for statement (leaf, internal node, root), on
// bit sets of which voxels are active and which values are negative instead
// of OpenVDB's nodes.
#include "src/volume/SignedFill.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>
#include <vector>

#include "src/util/Error.h"
#include "src/volume/LeafMask.h"

namespace vdbdag {
namespace {

using Origin = SignedFillTree::Origin;  // compared as OpenVDB's Coord: x, then y, then z

Origin alignDown(const Origin& c, int log2) {
    const int32_t m = ~((int32_t(1) << log2) - 1);
    return {c[0] & m, c[1] & m, c[2] & m};
}

// An internal node of 2^(3 log2Dim) slots: which hold a child, each child's
// first and last values' signs, and after the fill which tiles are inside.
struct Node {
    std::vector<bool> child, childFirst, childLast, inside;
    bool first = false, last = false;
    explicit Node(unsigned log2Dim)
        : child(size_t(1) << (3 * log2Dim)), childFirst(child.size()), childLast(child.size()), inside(child.size()) {}
};

void fillNode(Node& node, unsigned log2Dim) {
    const size_t n = node.child.size();
    size_t first = 0;
    while (!node.child[first]) ++first;  // a node is made by its children: one is there
    bool xInside = node.childFirst[first], yInside = xInside, zInside = xInside;
    const unsigned dim = 1u << log2Dim;
    for (unsigned x = 0; x != dim; ++x) {
        const size_t x00 = size_t(x) << (2 * log2Dim);
        if (node.child[x00]) xInside = node.childLast[x00];
        yInside = xInside;
        for (unsigned y = 0; y != dim; ++y) {
            const size_t xy0 = x00 + (size_t(y) << log2Dim);
            if (node.child[xy0]) yInside = node.childLast[xy0];
            zInside = yInside;
            for (unsigned z = 0; z != dim; ++z) {
                const size_t xyz = xy0 + z;
                if (node.child[xyz]) zInside = node.childLast[xyz];
                else node.inside[xyz] = zInside;
            }
        }
    }
    node.first = node.child[0] ? node.childFirst[0] : bool(node.inside[0]);
    node.last = node.child[n - 1] ? node.childLast[n - 1] : bool(node.inside[n - 1]);
}

// The slot of a child at `c` in the node at `o` (OpenVDB's coordToOffset).
size_t slotOf(const Origin& c, const Origin& o, unsigned log2Dim, unsigned childLog2) {
    const auto at = [&](int a) { return size_t(uint32_t(c[a] - o[a]) >> childLog2); };
    return at(0) << (2 * log2Dim) | at(1) << log2Dim | at(2);
}

// The nodes of 2^(3 log2Dim) slots of 2^childLog2 voxels holding
// `children` (origin -> child; ends(child): its first and last values'
// signs), filled.
template <typename Children, typename Ends>
std::map<Origin, Node> fillParents(const Children& children, unsigned log2Dim, unsigned childLog2, Ends&& ends) {
    std::map<Origin, Node> parents;
    for (const auto& [origin, child] : children) {
        const Origin o = alignDown(origin, int(log2Dim + childLog2));
        Node& node = parents.try_emplace(o, log2Dim).first->second;
        const size_t s = slotOf(origin, o, log2Dim, childLog2);
        const auto [first, last] = ends(child);
        node.child[s] = true, node.childFirst[s] = first, node.childLast[s] = last;
    }
    for (auto& [origin, node] : parents) fillNode(node, log2Dim);
    return parents;
}

Origin slotOrigin(const Origin& o, size_t slot, unsigned log2Dim, unsigned childLog2) {
    const size_t mask = (size_t(1) << log2Dim) - 1;
    return {o[0] + int32_t((slot >> (2 * log2Dim)) << childLog2), o[1] + int32_t(((slot >> log2Dim) & mask) << childLog2),
            o[2] + int32_t((slot & mask) << childLog2)};
}

template <typename T>
std::optional<InactiveLayer> fillTyped(const GridTopology& active, const LayerValues& values, std::span<const uint8_t> backgroundBytes,
                                       const FillParallel& parallel) {
    if (!active.tiles.empty() || backgroundBytes.size() != sizeof(T)) return std::nullopt;
    T background;
    std::memcpy(&background, backgroundBytes.data(), sizeof(T));
    if (!(background > T(0)) || !std::isfinite(background)) return std::nullopt;
    const T insideValue = -background;

    // The leaves, from the active bricks (grouped by leaf: sorted by their
    // leaf's origin, as OpenVDB's Coord orders them) and their values' signs.
    struct Leaf {
        SignedFillTree::LeafBits active{}, negative{};
    };
    std::vector<std::pair<Origin, size_t>> byLeaf(active.bricks.size());  // (leaf origin, brick)
    std::vector<size_t> firstValue(active.bricks.size());
    size_t count = 0;
    for (size_t k = 0; k < active.bricks.size(); ++k) {
        const Brick& b = active.bricks[k];
        byLeaf[k] = {alignDown({b.x, b.y, b.z}, 3), k};
        firstValue[k] = count;
        count += size_t(std::popcount(b.mask));
    }
    if (count * sizeof(T) != values.bricks.size()) throw Error("internal error: the active values do not match the active voxels");
    std::sort(byLeaf.begin(), byLeaf.end());
    std::vector<size_t> groupStart;  // each leaf's first entry of byLeaf
    for (size_t g = 0; g < byLeaf.size(); ++g)
        if (g == 0 || byLeaf[g].first != byLeaf[g - 1].first) groupStart.push_back(g);
    groupStart.push_back(byLeaf.size());
    // Each leaf alone: its fill and its inside voxels' bricks (x fastest, then y, then z).
    struct LeafOut {
        SignedFillTree::LeafFill fill;
        std::array<uint64_t, 8> bricks{};
    };
    std::vector<LeafOut> leafOut(groupStart.size() - 1);
    const auto fillOne = [&](size_t l) {
        Leaf leaf;
        for (size_t g = groupStart[l]; g < groupStart[l + 1]; ++g) {
            const Brick& b = active.bricks[byLeaf[g].second];
            size_t next = firstValue[byLeaf[g].second];
            for (uint64_t bits = b.mask; bits; bits &= bits - 1) {
                const int i = std::countr_zero(bits);
                const size_t n = SignedFillTree::leafIndex(unsigned(b.x & 7) + unsigned(i & 3), unsigned(b.y & 7) + unsigned((i >> 2) & 3),
                                                           unsigned(b.z & 7) + unsigned(i >> 4));
                T v;
                std::memcpy(&v, &values.bricks[next++ * sizeof(T)], sizeof(T));
                SignedFillTree::set(leaf.active, n);
                if (v < T(0)) SignedFillTree::set(leaf.negative, n);
            }
        }
        LeafOut& o = leafOut[l];
        o.fill = SignedFillTree::fillLeaf(leaf.active, leaf.negative);
        if (o.fill.inside == SignedFillTree::LeafBits{}) return;
        for (unsigned k = 0; k < 8; ++k) o.bricks[k] = brickOfLeafMask(o.fill.inside.data(), k);
    };
    if (parallel) parallel(leafOut.size(), fillOne);
    else
        for (size_t l = 0; l < leafOut.size(); ++l) fillOne(l);
    // The layer: each leaf's inside voxels as bricks, then the inside tiles.
    InactiveLayer out;
    SignedFillTree tree;
    for (size_t l = 0; l < leafOut.size(); ++l) {
        const Origin& origin = byLeaf[groupStart[l]].first;
        tree.addLeaf(origin, leafOut[l].fill);
        for (int k = 0; k < 8; ++k)
            if (const uint64_t mask = leafOut[l].bricks[size_t(k)])
                out.topology.bricks.push_back({origin[0] + (k & 1) * 4, origin[1] + ((k >> 1) & 1) * 4, origin[2] + (k >> 2) * 4, mask});
    }
    out.topology.tiles = tree.insideTiles();
    // Every value -|background|.
    size_t inside = out.topology.tiles.size();
    for (const Brick& b : out.topology.bricks) inside += size_t(std::popcount(b.mask));
    std::vector<uint8_t> all(inside * sizeof(T));
    for (size_t i = 0; i < inside; ++i) std::memcpy(&all[i * sizeof(T)], &insideValue, sizeof(T));
    out.values.tiles.assign(all.end() - long(out.topology.tiles.size() * sizeof(T)), all.end());
    all.resize(all.size() - out.topology.tiles.size() * sizeof(T));
    out.values.bricks = std::move(all);
    return out;
}

} // namespace

SignedFillTree::LeafFill SignedFillTree::fillLeaf(const LeafBits& active, const LeafBits& negative) {
    LeafFill out;
    size_t first = 512;
    for (size_t w = 0; w < 8 && first == 512; ++w)
        if (active[w]) first = w * 64 + size_t(std::countr_zero(active[w]));
    if (first == 512) throw Error("internal error: a leaf with no active voxel has no fill");
    bool xInside = test(negative, first), yInside = xInside, zInside = xInside;
    for (unsigned x = 0; x != 8; ++x) {
        if (active[x] & 1) xInside = negative[x] & 1;  // element (x, 0, 0)
        yInside = xInside;
        for (unsigned y = 0; y != 8; ++y) {
            const unsigned rowActive = unsigned(active[x] >> (8 * y)) & 0xFFu, rowNegative = unsigned(negative[x] >> (8 * y)) & 0xFFu;
            if (rowActive & 1u) yInside = rowNegative & 1u;  // element (x, y, 0)
            zInside = yInside;
            for (unsigned z = 0; z != 8; ++z) {
                if ((rowActive >> z) & 1u) zInside = (rowNegative >> z) & 1u;
                else if (zInside) out.inside[x] |= uint64_t(1) << (8 * y + z);
            }
        }
    }
    const auto negativeAt = [&](size_t i) { return test(active, i) ? test(negative, i) : test(out.inside, i); };
    out.first = negativeAt(0);
    out.last = negativeAt(511);
    return out;
}

void SignedFillTree::addLeaf(const Origin& origin, const LeafFill& fill) {
    if ((origin[0] | origin[1] | origin[2]) & 7) throw Error("internal error: a leaf origin that is not a multiple of 8");
    if (!leaves_.try_emplace(origin, fill.first, fill.last).second) throw Error("internal error: a leaf added twice");
}

std::vector<Tile> SignedFillTree::insideTiles() const {
    // The internal nodes of 128^3 (16^3 slots of leaves), then of 4096^3
    // (32^3 slots of 128^3 nodes), each filled once its children are.
    const std::map<Origin, Node> lower = fillParents(leaves_, 4, 3, [](const std::pair<bool, bool>& ends) { return ends; });
    const std::map<Origin, Node> upper = fillParents(lower, 5, 7, [](const Node& n) { return std::pair{n.first, n.last}; });
    std::vector<Tile> tiles;
    const auto pushTiles = [&](const std::map<Origin, Node>& nodes, unsigned log2Dim, unsigned childLog2) {
        for (const auto& [origin, node] : nodes)
            for (size_t s = 0; s < node.inside.size(); ++s)
                if (!node.child[s] && node.inside[s]) {
                    const Origin c = slotOrigin(origin, s, log2Dim, childLog2);
                    tiles.push_back({c[0], c[1], c[2], uint8_t(childLog2)});
                }
    };
    pushTiles(lower, 4, 3);
    pushTiles(upper, 5, 7);
    // The root: runs of missing 4096^3 nodes along z between two inside faces.
    constexpr int64_t kTop = int64_t(1) << 12;
    for (auto a = upper.begin(), b = upper.empty() ? upper.end() : std::next(a); b != upper.end(); ++a, ++b) {
        const Origin& p = a->first;
        const Origin& q = b->first;
        if (p[0] != q[0] || p[1] != q[1] || int64_t(q[2]) - p[2] == kTop) continue;
        if (!a->second.last || !b->second.first) continue;
        for (int64_t z = int64_t(p[2]) + kTop; z != q[2]; z += kTop) tiles.push_back({p[0], p[1], int32_t(z), uint8_t(12)});
    }
    return tiles;
}

std::optional<InactiveLayer> signedFillInactive(const GridTopology& active, const LayerValues& values, ValueType type,
                                                std::span<const uint8_t> background, const FillParallel& parallel) {
    if (active.bricks.empty()) return std::nullopt;
    if (type == ValueType::Float) return fillTyped<float>(active, values, background, parallel);
    if (type == ValueType::Double) return fillTyped<double>(active, values, background, parallel);
    return std::nullopt;
}

bool sameInactiveLayer(const GridTopology& a, const LayerValues& aValues, const GridTopology& b, const LayerValues& bValues, ValueType type) {
    const size_t vs = valueSize(type);
    // Each layer's bricks by corner (mask, values) and tiles by corner and size (value).
    using Key = std::tuple<int32_t, int32_t, int32_t>;
    struct Bricks {
        std::map<Key, std::pair<uint64_t, std::vector<uint8_t>>> bricks;
        std::map<std::tuple<int32_t, int32_t, int32_t, uint8_t>, std::vector<uint8_t>> tiles;
    };
    const auto index = [&](const GridTopology& t, const LayerValues& v, Bricks& out) {
        size_t next = 0;
        for (const Brick& br : t.bricks) {
            const size_t n = size_t(std::popcount(br.mask)) * vs;
            if (next + n > v.bricks.size()) return false;
            std::vector<uint8_t> bytes(v.bricks.begin() + long(next), v.bricks.begin() + long(next + n));
            next += n;
            if (!out.bricks.try_emplace(Key{br.x, br.y, br.z}, br.mask, std::move(bytes)).second) return false;
        }
        if (next != v.bricks.size() || t.tiles.size() * vs != v.tiles.size()) return false;
        for (size_t i = 0; i < t.tiles.size(); ++i) {
            const Tile& tile = t.tiles[i];
            std::vector<uint8_t> bytes(v.tiles.begin() + long(i * vs), v.tiles.begin() + long((i + 1) * vs));
            if (!out.tiles.try_emplace(std::tuple{tile.x, tile.y, tile.z, tile.log2Size}, std::move(bytes)).second) return false;
        }
        return true;
    };
    Bricks x, y;
    if (!index(a, aValues, x) || !index(b, bValues, y)) return false;
    return x.bricks == y.bricks && x.tiles == y.tiles;
}

} // namespace vdbdag
