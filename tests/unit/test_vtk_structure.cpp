// `vdbdag export --structure`: per level, the node instances must be exactly
// the occupied cells of the sparse voxel octree over the grid's voxels (a
// brute-force count from OpenVDB's voxels and tiles); refcounts must equal
// the distinct (parent node, stored slot) pairs that lead to a node; every
// instance of a brick must be the same stored mask once its `mirror`
// reflection is undone (reflection written out here, independently); the
// unique-node mode must list every node once with instance counts that add
// up to the same octree.
#include <gtest/gtest.h>

#include <bit>
#include <map>
#include <set>

#include <openvdb/tools/LevelSetSphere.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>

#include "VtkTestSupport.h"

using namespace vtktest;

namespace {

openvdb::FloatGrid::Ptr structureGrid() {
    openvdb::initialize();
    auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(10.0f, openvdb::Vec3f(3.0f, -2.0f, 5.0f), 1.0f, 2.0f);
    grid->setName("shape");
    grid->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
    grid->transform().postTranslate(openvdb::Vec3d(1.0, 2.0, -4.0));
    grid->tree().addTile(1, openvdb::Coord(40, 0, 8), 1.0f, true);
    grid->tree().setValueOn(openvdb::Coord(-30, 17, 3), 0.25f);
    return grid;
}

using Key = std::array<int64_t, 3>;

// Brute force: the octree cells of size 2^s (relative to `origin`) holding an
// active voxel, or lying inside (or being) an active tile at least that large.
std::set<Key> occupiedCells(const openvdb::FloatGrid& grid, const openvdb::Coord& origin, unsigned s) {
    std::set<Key> cells;
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) {
            const openvdb::Coord c = it.getCoord() - origin;
            cells.insert({int64_t(c.x()) >> s, int64_t(c.y()) >> s, int64_t(c.z()) >> s});
        } else {
            const openvdb::CoordBBox box = it.getBoundingBox();
            if ((int64_t(1) << s) < int64_t(box.dim().x())) continue;  // a solid node has no children
            const openvdb::Coord c = box.min() - origin;
            cells.insert({int64_t(c.x()) >> s, int64_t(c.y()) >> s, int64_t(c.z()) >> s});
        }
    }
    return cells;
}

uint64_t reflectMask(uint64_t mask, unsigned m) {  // bit x + 4y + 16z, mirrored per axis
    uint64_t out = 0;
    for (int bit = 0; bit < 64; ++bit) {
        if (!((mask >> bit) & 1)) continue;
        int x = bit & 3, y = (bit >> 2) & 3, z = bit >> 4;
        if (m & 1) x = 3 - x;
        if (m & 2) y = 3 - y;
        if (m & 4) z = 3 - z;
        out |= uint64_t(1) << (x + 4 * y + 16 * z);
    }
    return out;
}

struct Cell {
    openvdb::Coord corner;
    int size;
    int nodeId, refcount, mirror, level;
    int64_t instances;
};

std::vector<Cell> cellsOf(vtkUnstructuredGrid* ug, const openvdb::math::Transform& xf) {
    std::vector<Cell> out;
    auto* cd = ug->GetCellData();
    for (const char* f : {"level", "node_id", "refcount", "instances", "mirror", "solid"}) EXPECT_NE(cd->GetArray(f), nullptr) << f;
    for (vtkIdType c = 0; c < ug->GetNumberOfCells(); ++c) {
        const openvdb::CoordBBox box = cellVoxels(ug, c, xf);
        out.push_back({box.min(), box.dim().x(), int(cd->GetArray("node_id")->GetTuple1(c)), int(cd->GetArray("refcount")->GetTuple1(c)),
                       int(cd->GetArray("mirror")->GetTuple1(c)), int(cd->GetArray("level")->GetTuple1(c)), int64_t(cd->GetArray("instances")->GetTuple1(c))});
    }
    return out;
}

} // namespace

TEST(VtkStructure, LevelsAreTheOctreeCellsWithConsistentRefcountsAndMirrors) {
    auto grid = structureGrid();
    const fs::path in = workDir() / "shape.vdb", enc = workDir() / "shape.ssvdag", out = workDir() / "shape_structure.vtm";
    writeGrids(in, {grid});
    const auto encoded = runCli("encode " + in.string() + " -o " + enc.string());
    ASSERT_EQ(encoded.exitCode, 0) << encoded.err;
    auto r = runCli("export " + enc.string() + " --structure -o " + out.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    auto blocks = readVtm(out);
    const unsigned levels = blocks->GetNumberOfBlocks();
    ASSERT_GE(levels, 3u);
    std::vector<std::vector<Cell>> cells(levels);
    for (unsigned i = 0; i < levels; ++i) {
        auto* ug = vtkUnstructuredGrid::SafeDownCast(blocks->GetBlock(i));
        ASSERT_NE(ug, nullptr);
        cells[i] = cellsOf(ug, grid->transform());
    }
    ASSERT_EQ(cells[0].size(), 1u);
    const openvdb::Coord origin = cells[0][0].corner;
    const int rootSize = cells[0][0].size;
    ASSERT_EQ(rootSize, 4 << (levels - 1));
    EXPECT_EQ(cells[0][0].refcount, 1);

    // Every level: exactly the occupied octree cells (brute force from OpenVDB), aligned, of the level's size.
    std::vector<std::map<Key, const Cell*>> byKey(levels);
    for (unsigned i = 0; i < levels; ++i) {
        const unsigned s = unsigned(std::countr_zero(unsigned(rootSize))) - i;
        const std::set<Key> expected = occupiedCells(*grid, origin, s);
        EXPECT_EQ(cells[i].size(), expected.size()) << "level " << i;
        for (const Cell& c : cells[i]) {
            EXPECT_EQ(c.size, 1 << s);
            EXPECT_EQ(c.level, int(i));
            const openvdb::Coord rel = c.corner - origin;
            const Key key{rel.x() >> s, rel.y() >> s, rel.z() >> s};
            EXPECT_EQ(openvdb::Coord(int(key[0] << s), int(key[1] << s), int(key[2] << s)), rel) << "unaligned node";
            EXPECT_TRUE(expected.count(key)) << "level " << i << " node at " << c.corner << " covers no active voxel";
            byKey[i][key] = &c;
        }
    }

    // Refcount = distinct (parent node, stored slot) pairs leading to the node; each such pair always leads to the same node.
    for (unsigned i = 1; i < levels; ++i) {
        const unsigned s = unsigned(std::countr_zero(unsigned(rootSize))) - i;
        std::map<std::pair<int, unsigned>, int> pairToChild;
        std::map<int, std::set<std::pair<int, unsigned>>> parentsOf;
        std::map<int, int64_t> instancesOf;
        std::map<int, int> refcountOf;
        for (const Cell& c : cells[i]) {
            const openvdb::Coord rel = c.corner - origin;
            const Cell* parent = byKey[i - 1].at({rel.x() >> (s + 1), rel.y() >> (s + 1), rel.z() >> (s + 1)});
            const unsigned spatial = unsigned(((rel.x() >> s) & 1) | (((rel.y() >> s) & 1) << 1) | (((rel.z() >> s) & 1) << 2));
            const std::pair<int, unsigned> pair{parent->nodeId, spatial ^ unsigned(parent->mirror)};  // stored slot
            const auto [it, fresh] = pairToChild.emplace(pair, c.nodeId);
            EXPECT_EQ(it->second, c.nodeId) << "parent node " << pair.first << " slot " << pair.second << " leads to two nodes";
            parentsOf[c.nodeId].insert(pair);
            instancesOf[c.nodeId] += 1;
            if (refcountOf.count(c.nodeId)) { EXPECT_EQ(refcountOf[c.nodeId], c.refcount); }
            refcountOf[c.nodeId] = c.refcount;
            (void)fresh;
        }
        for (const auto& [id, parents] : parentsOf) EXPECT_EQ(uint64_t(refcountOf[id]), parents.size()) << "level " << i << " node " << id;
        for (const Cell& c : cells[i]) EXPECT_EQ(c.instances, instancesOf[c.nodeId]);
    }

    // Bricks: undoing each instance's mirror gives one stored mask per node id, distinct per id.
    auto acc = grid->getConstAccessor();
    std::map<int, uint64_t> storedOf;
    for (const Cell& c : cells[levels - 1]) {
        uint64_t spatial = 0;
        for (int bit = 0; bit < 64; ++bit)
            if (acc.isValueOn(c.corner.offsetBy(bit & 3, (bit >> 2) & 3, bit >> 4))) spatial |= uint64_t(1) << bit;
        const uint64_t stored = reflectMask(spatial, unsigned(c.mirror));
        const auto [it, fresh] = storedOf.emplace(c.nodeId, stored);
        EXPECT_EQ(it->second, stored) << "brick node " << c.nodeId << " at " << c.corner;
        (void)fresh;
    }
    std::set<uint64_t> distinct;
    for (const auto& [id, mask] : storedOf) distinct.insert(mask);
    EXPECT_EQ(distinct.size(), storedOf.size());
    EXPECT_LT(storedOf.size(), cells[levels - 1].size()) << "a sphere shares bricks";

    // One cell per unique node: instance counts add up to the octree's cells.
    const fs::path unique = workDir() / "shape_unique.vtm";
    r = runCli("export " + enc.string() + " --structure --unique-nodes -o " + unique.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    auto ublocks = readVtm(unique);
    ASSERT_EQ(ublocks->GetNumberOfBlocks(), levels);
    for (unsigned i = 0; i < levels; ++i) {
        const std::vector<Cell> u = cellsOf(vtkUnstructuredGrid::SafeDownCast(ublocks->GetBlock(i)), grid->transform());
        std::set<int> ids;
        int64_t total = 0;
        for (const Cell& c : u) {
            ids.insert(c.nodeId);
            total += c.instances;
        }
        EXPECT_EQ(ids.size(), u.size()) << "level " << i;
        std::set<int> idsPerInstance;
        for (const Cell& c : cells[i]) idsPerInstance.insert(c.nodeId);
        EXPECT_EQ(ids, idsPerInstance) << "level " << i;
        EXPECT_EQ(uint64_t(total), cells[i].size()) << "level " << i;
    }
}
