// Exact (unquantised) shading normals for `encode --normals K`, computed
// with OpenVDB's accessors and handed to the core as plain vectors in the
// record's input order (GridRecord::Normals), one per active voxel and tile:
//  - from a float/double level set (or any scalar field): the gradient by
//    central differences in index space; where a neighbour along an axis is
//    inactive (the narrow band's edge) that axis falls back to a one-sided
//    difference towards the active side (counted); the gradient is mapped to
//    world space by the transform's inverse Jacobian transpose, normalised.
//    A tile is evaluated at its centre voxel. A zero gradient (flat region)
//    stays a zero vector: the ONV encoder stores +z and counts it.
//  - from a vec3 normal grid: its values, normalised (zero stays zero).
//
// The per-voxel rules below are the one definition both readers use: the
// whole-grid import (an OpenVDB accessor) and the region-by-region reader
// (VdbCubes: the cube's leaves and a one-voxel halo from the scratch file).
#pragma once
#include <array>
#include <atomic>
#include <cmath>
#include <vector>

#include <openvdb/openvdb.h>
#include <tbb/parallel_for.h>

#include "src/volume/GridRecord.h"

namespace vdbdag::bridge::detail {

using NormalVector = std::array<float, 3>;

inline NormalVector normalised(const openvdb::Vec3d& v) {
    const double len = v.length();
    if (!(len > 0.0) || !std::isfinite(len)) return {0.f, 0.f, 0.f};
    return {float(v.x() / len), float(v.y() / len), float(v.z() / len)};
}

// Whether active voxel `c` is at the band's edge: on some axis one of its
// two neighbours is inactive. `active(coord)` -> bool.
template <typename Active>
bool bandEdgeAt(Active&& active, const openvdb::Coord& c) {
    for (int axis = 0; axis < 3; ++axis) {
        openvdb::Coord plus = c, minus = c;
        plus[axis] += 1;
        minus[axis] -= 1;
        if (!active(plus) || !active(minus)) return true;
    }
    return false;
}

// The gradient normal at active voxel `c` (see above), with
// `probe(coord, ValueT&)` -> bool as OpenVDB's probeValue (the value, and
// whether the voxel is active); `edge` is set where an axis was one-sided.
// `map` is the grid's transform's base map (taken once: baseMap() copies a
// shared pointer).
template <typename ValueT, typename Probe>
NormalVector gradientNormalAt(Probe&& probe, const openvdb::math::MapBase& map, const openvdb::Coord& c, bool& edge) {
    openvdb::Vec3d g;
    ValueT centre{};
    probe(c, centre);
    for (int axis = 0; axis < 3; ++axis) {
        openvdb::Coord plus = c, minus = c;
        plus[axis] += 1;
        minus[axis] -= 1;
        ValueT vp{}, vm{};
        const bool onP = probe(plus, vp), onM = probe(minus, vm);
        if (onP && onM) {
            g[axis] = 0.5 * (double(vp) - double(vm));
        } else {
            edge = true;
            g[axis] = onP ? double(vp) - double(centre) : onM ? double(centre) - double(vm) : 0.0;
        }
    }
    return normalised(map.applyIJT(g, map.applyMap(c.asVec3d())));  // Transform::indexToWorld(c)
}

// A leaf and the voxels beside its six faces, as a six-neighbour stencil
// reads them: leaf voxel (x, y, z), -1..8 on each axis, at haloIndex(x, y,
// z) of a 10^3 block (its edges and corners are never read).
inline size_t haloIndex(int x, int y, int z) { return size_t((x + 1) + 10 * (y + 1) + 100 * (z + 1)); }
// Calls face(offset, cell) for each of the six faces: `offset` the origin
// of the leaf beside it relative to this leaf's, `cell(f)` calling f(local)
// for the face's 64 voxels (leaf-relative coordinates, -1 or 8 on the axis).
template <typename Face>
void forEachHaloFace(Face&& face) {
    for (int axis = 0; axis < 3; ++axis)
        for (int side : {-1, 8}) {
            openvdb::Coord offset(0);
            offset[axis] = side < 0 ? -8 : 8;
            face(offset, [&](auto&& f) {
                for (int u = 0; u < 8; ++u)
                    for (int w = 0; w < 8; ++w) {
                        openvdb::Coord local;
                        local[axis] = side, local[(axis + 1) % 3] = u, local[(axis + 2) % 3] = w;
                        f(local);
                    }
            });
        }
}

// The active voxels at the band's edge (bandEdgeAt) of the whole grid, from
// the value masks alone: each leaf and the voxels beside its six faces in a
// 10^3 block. No ValueAccessor: one caches the leaves it passes, and
// caching a leaf of a grid read with delayed loading loads its values; a
// leaf's mask and the tree's own isValueOn do not.
template <typename GridT>
uint64_t countBandEdges(const GridT& grid) {
    using LeafT = typename GridT::TreeType::LeafNodeType;
    const auto& tree = grid.tree();
    std::vector<const LeafT*> leaves;
    for (auto it = tree.cbeginLeaf(); it; ++it) leaves.push_back(it.getLeaf());
    std::atomic<uint64_t> edges{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 64), [&](const auto& range) {
        std::array<uint8_t, 1000> on;  // haloIndex
        uint64_t local = 0;
        for (size_t i = range.begin(); i != range.end(); ++i) {
            const LeafT& leaf = *leaves[i];
            const openvdb::Coord origin = leaf.origin();
            on.fill(0);
            for (auto n = leaf.getValueMask().beginOn(); n; ++n) {
                const openvdb::Coord c = LeafT::offsetToLocalCoord(n.pos());
                on[haloIndex(c.x(), c.y(), c.z())] = 1;
            }
            forEachHaloFace([&](const openvdb::Coord& offset, auto&& cells) {
                const LeafT* other = tree.probeConstLeaf(origin + offset);
                const bool tileOn = !other && tree.isValueOn(origin + offset);  // no leaf there: one tile (or none) holds all of it
                cells([&](const openvdb::Coord& l) {
                    on[haloIndex(l.x(), l.y(), l.z())] = other ? other->getValueMask().isOn(LeafT::coordToOffset(origin + l)) : tileOn;
                });
            });
            for (auto n = leaf.getValueMask().beginOn(); n; ++n)
                if (bandEdgeAt([&](const openvdb::Coord& c) { return on[haloIndex(c.x(), c.y(), c.z())] != 0; }, LeafT::offsetToLocalCoord(n.pos()))) ++local;
        }
        edges += local;
    });
    return edges.load();
}

// The normal a vec3 normal grid's value gives.
template <typename VecT>
NormalVector vectorNormal(const VecT& v) {
    return normalised(openvdb::Vec3d(double(v[0]), double(v[1]), double(v[2])));
}

// `topology` is the grid's active topology as imported (bricks and tiles).
GridRecord::Normals gradientNormals(const openvdb::FloatGrid& grid, const GridTopology& topology);
GridRecord::Normals gradientNormals(const openvdb::DoubleGrid& grid, const GridTopology& topology);
GridRecord::Normals gridNormals(const openvdb::Vec3SGrid& grid, const GridTopology& topology);
GridRecord::Normals gridNormals(const openvdb::Vec3DGrid& grid, const GridTopology& topology);
GridRecord::Normals gridNormals(const openvdb::Vec3IGrid& grid, const GridTopology& topology);

} // namespace vdbdag::bridge::detail
