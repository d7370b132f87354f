// Normals (--normals K): on a sphere level set the decoded ONV normal of
// every voxel, read back from the file in attribute order, is checked
// against the closed form (p - c)/|p - c| and, where all six neighbours
// are active, against the central-difference gradient computed here with
// OpenVDB's accessor (within the ONV bound 0.95° x 2^((16-k)/2)); normals
// from a vec3 normal grid; no section without --normals; corrupted
// sections refused with one line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "src/attributes/NormalChannel.h"
#include "src/attributes/OctahedralNormal.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "src/pipeline/CubeEncoder.h"
#include "vdb_bridge/VdbCubes.h"
#include "vdb_bridge/VdbImport.h"

using namespace vdbdag;
namespace fs = std::filesystem;

namespace {

const openvdb::Vec3f kCentre(1.3f, -0.7f, 2.1f);

fs::path tempDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_normals_" + std::to_string(getpid()));
        fs::remove_all(d);  // a finished process with the same PID may have left it
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

// A sphere of radius 12 world units with 0.5-unit voxels (so the world
// transform matters), narrow band 3 voxels.
openvdb::FloatGrid::Ptr sphere() {
    auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(12.0f, kCentre, 0.5f, 3.0f);
    g->setName("ball");
    return g;
}

fs::path writeVdb(const std::string& name, const openvdb::GridPtrVec& grids) {
    openvdb::initialize();
    const fs::path p = tempDir() / name;
    openvdb::io::File(p.string()).write(grids);
    return p;
}

// Calls fn(coord, entry) for every voxel of the DAG in attribute order
// (DESIGN.md invariant 2: stored bit b of a brick under mirror m is the
// spatial voxel with the axes in m flipped).
template <typename Fn>
void forEachEntry(const encoding::CompactDag& dag, Fn fn) {
    encoding::visitInAttributeOrder(
        dag,
        [&](const encoding::BrickInstance& b) {
            uint64_t entry = b.firstEntry;
            for (uint64_t bits = b.storedMask; bits; bits &= bits - 1, ++entry) {
                const int bit = std::countr_zero(bits);
                int x = bit & 3, y = (bit >> 2) & 3, z = bit >> 4;
                if (b.mirror & 1u) x = 3 - x;
                if (b.mirror & 2u) y = 3 - y;
                if (b.mirror & 4u) z = 3 - z;
                fn(openvdb::Coord(int(b.x) + x, int(b.y) + y, int(b.z) + z), entry);
            }
        },
        [&](int64_t, int64_t, int64_t, unsigned, uint64_t) { FAIL() << "the sphere has no active tiles"; });
}

double angle(const std::array<float, 3>& a, const openvdb::Vec3d& b) {
    return attributes::angleDegrees(a, {float(b.x()), float(b.y()), float(b.z())});
}

// The whole grid in memory, or (byCubes) read region by region in cubes of
// 16^3, each cube's normals from its voxels and a one-voxel halo.
format::SsvdagScene encodeFile(const fs::path& in, unsigned bits, const std::string& normalGrid = "", bool byCubes = false) {
    bridge::ImportOptions io;
    io.normals = bits != 0;
    io.normalGrid = normalGrid;
    pipeline::EncodeOptions options;
    options.normalBits = bits;
    if (byCubes) {
        bridge::VdbCubeInput input = bridge::openVdbCubes(in.string(), io);
        pipeline::CubeBudget budget;
        budget.cubeLog2 = 4;
        return format::readScene(format::writeScene(pipeline::encodeSourcesByCubes(std::move(input.grids), input.fileMetadata, options, budget)),
                                 "normals test");
    }
    return format::readScene(format::writeScene(pipeline::encodeVolume(bridge::importVdb(in.string(), io).volume, options)), "normals test");
}

} // namespace

TEST(Normals, SphereGradientNormalsMatchTheClosedFormAndTheOnvBound) {
    const auto grid = sphere();
    const fs::path in = writeVdb("sphere.vdb", {grid});
    auto acc = grid->getConstAccessor();
    const std::vector<std::pair<unsigned, bool>> runs{{10, false}, {12, false}, {16, false}, {24, false}, {32, false}, {16, true}, {32, true}};
    for (const auto& [k, byCubes] : runs) {
        SCOPED_TRACE(byCubes ? "cube by cube" : "whole grid");
        const auto scene = encodeFile(in, k, "", byCubes);
        const format::EncodedGrid& g = scene.grids[0];
        ASSERT_TRUE(g.normals.has_value());
        const attributes::NormalChannel& n = *g.normals;
        EXPECT_EQ(n.bits, k);
        EXPECT_EQ(n.entryCount(), grid->activeVoxelCount());
        const double onvBound = 0.95 * std::pow(2.0, (16.0 - double(k)) / 2.0);
        EXPECT_LE(n.report.maxAngleDegrees, onvBound);
        EXPECT_GT(n.report.oneSided, 0u) << "the narrow band's edge";
        uint64_t interior = 0, visited = 0;
        double maxClosed = 0, sumClosed = 0;
        forEachEntry(g.active.dag, [&](const openvdb::Coord& c, uint64_t entry) {
            ++visited;
            const std::array<float, 3> decoded = n.decode(entry);
            const openvdb::Vec3d p = grid->indexToWorld(c);
            const double closed = angle(decoded, (p - openvdb::Vec3d(kCentre)).unit());
            maxClosed = std::max(maxClosed, closed);
            sumClosed += closed;
            // Independent central difference where the whole stencil is active.
            openvdb::Vec3d grad;
            for (int a = 0; a < 3; ++a) {
                openvdb::Coord hi = c, lo = c;
                hi[a] += 1;
                lo[a] -= 1;
                if (!acc.isValueOn(hi) || !acc.isValueOn(lo)) return;
                grad[a] = 0.5 * (double(acc.getValue(hi)) - double(acc.getValue(lo)));
            }
            ++interior;
            ASSERT_LE(angle(decoded, grad), onvBound * 1.001 + 1e-4) << "k=" << k << " at " << c;
        });
        EXPECT_EQ(visited, n.entryCount());
        EXPECT_GT(interior, visited / 2);
        // Closed form: discretisation (one-sided at the band edge) plus the ONV bound.
        EXPECT_LE(maxClosed, 4.0 + onvBound) << "k=" << k;
        EXPECT_LE(sumClosed / double(visited), 1.0 + onvBound / 2) << "k=" << k;
    }
}

TEST(Normals, FromAVec3NormalGridOnItsOwnGeometry) {
    const auto ls = sphere();
    auto normals = openvdb::Vec3SGrid::create(openvdb::Vec3s(0));
    normals->setName("N");
    normals->setTransform(ls->transform().copy());
    auto acc = normals->getAccessor();
    for (auto it = ls->cbeginValueOn(); it; ++it) {
        if (std::fabs(*it) > 0.6f) continue;  // a thin shell only
        const openvdb::Vec3d d = ls->indexToWorld(it.getCoord()) - openvdb::Vec3d(kCentre);
        acc.setValue(it.getCoord(), openvdb::Vec3s(d * 3.0));  // not unit length: normalised on import
    }
    acc.setValue(openvdb::Coord(1000, 0, 0), openvdb::Vec3s(0.f));  // no direction -> +z, counted
    const fs::path in = writeVdb("normal_grid.vdb", {ls, normals});
    for (bool byCubes : {false, true}) {
        SCOPED_TRACE(byCubes ? "cube by cube" : "whole grid");
        const auto scene = encodeFile(in, 16, "N", byCubes);
        ASSERT_EQ(scene.grids.size(), 2u);
        const size_t ni = scene.grids[0].record.name == "N" ? 0 : 1;  // OpenVDB may reorder grids in the file
        EXPECT_FALSE(scene.grids[1 - ni].normals.has_value()) << "only the normal grid's geometry carries them";
        ASSERT_TRUE(scene.grids[ni].normals.has_value());
        const auto& n = *scene.grids[ni].normals;
        EXPECT_EQ(n.report.source, attributes::NormalReport::Source::NormalGrid);
        EXPECT_EQ(n.report.zeroLength, 1u);
        EXPECT_LE(n.report.maxAngleDegrees, 0.95);
        forEachEntry(scene.grids[ni].active.dag, [&](const openvdb::Coord& c, uint64_t entry) {
            const openvdb::Vec3d d = ls->indexToWorld(c) - openvdb::Vec3d(kCentre);
            if (c.x() == 1000) {
                const auto z = n.decode(entry);
                EXPECT_NEAR(z[2], 1.0f, 1e-6f);
                return;
            }
            ASSERT_LE(angle(n.decode(entry), d), 0.95) << c;
        });
    }
}

TEST(Normals, NoSectionWithoutTheOptionAndCorruptSectionsAreRefused) {
    const fs::path in = writeVdb("sphere2.vdb", {sphere()});
    const auto volume = bridge::importVdb(in.string()).volume;
    for (const auto& s : format::summarizeContainer(format::writeScene(pipeline::encodeVolume(volume)), "t"))
        EXPECT_NE(s.kind, format::SectionKind::Normals);

    bridge::ImportOptions io;
    io.normals = true;
    pipeline::EncodeOptions options;
    options.normalBits = 12;
    const auto good = format::sceneToSections(pipeline::encodeVolume(bridge::importVdb(in.string(), io).volume, options));
    // Each corruption is caught behind a valid checksum by the section reader.
    const std::vector<std::pair<std::string, std::function<void(std::vector<uint8_t>&)>>> corruptions{
        {"bits", [](std::vector<uint8_t>& d) { d[0] = 7; }},
        {"source", [](std::vector<uint8_t>& d) { d[1] = 9; }},
        {"entry count", [](std::vector<uint8_t>& d) { d[2] ^= 1; }},
        {"truncated", [](std::vector<uint8_t>& d) { d.resize(d.size() / 2); }},
        {"codes wider than k bits", [](std::vector<uint8_t>& d) { d[0] = 10; }},  // 12-bit codes read as 10-bit
    };
    for (const auto& [name, corrupt] : corruptions) {
        auto sections = good;
        bool found = false;
        for (auto& s : sections)
            if (s.kind == format::SectionKind::Normals) {
                corrupt(s.data);
                found = true;
            }
        ASSERT_TRUE(found);
        try {
            format::readScene(format::writeContainer(sections), "bad.ssvdag");
            ADD_FAILURE() << name << " accepted";
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.rfind("bad.ssvdag", 0), 0u) << m;
            EXPECT_NE(m.find("Normals"), std::string::npos) << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        }
    }
}

TEST(Normals, NormalsNeedAScalarGridOrANamedVec3Grid) {
    auto cd = openvdb::Vec3SGrid::create(openvdb::Vec3s(0));
    cd->setName("Cd");
    cd->tree().setValue(openvdb::Coord(0), openvdb::Vec3s(1.f));
    const fs::path in = writeVdb("colour_only.vdb", {cd, sphere()});
    bridge::ImportOptions io;
    io.normals = true;
    io.normalGrid = "ball";
    EXPECT_THROW(bridge::importVdb(in.string(), io), Error) << "a float grid is not a normal grid";
    io.normalGrid = "missing";
    EXPECT_THROW(bridge::importVdb(in.string(), io), Error);
    io.onlyGrids = {"Cd"};
    io.normalGrid = "";
    EXPECT_THROW(bridge::importVdb(in.string(), io), Error) << "no float grid to take a gradient of";
}
