// `vdbdag diff`: against itself -> all same, exit 0; against a lossy decode
// -> the encoder's own max error (encode --json), within the bound, every
// cell's a, b and error equal to OpenVDB's values; one voxel removed -> that
// voxel alone, only in A; a tile against the same region as a leaf with one
// changed voxel -> walked voxel by voxel. Read back with VTK's reader.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>
#include <openvdb/tools/LevelSetSphere.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>

#include "VtkTestSupport.h"

using namespace vtktest;

namespace {

openvdb::FloatGrid::Ptr ball(const std::string& name) {
    openvdb::initialize();
    auto grid = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(12.0f, openvdb::Vec3f(0.5f, -1.0f, 2.0f), 1.0f, 3.0f);
    grid->setName(name);
    grid->tree().addTile(1, openvdb::Coord(64, 0, 0), 7.5f, true);
    return grid;
}

uint64_t count(const nlohmann::json& grid, const char* status) { return grid["voxels"][status].get<uint64_t>(); }

} // namespace

TEST(VtkDiff, AFileAgainstItselfIsAllSame) {
    auto grid = ball("d");
    const fs::path in = workDir() / "self.vdb", enc = workDir() / "self.ssvdag", out = workDir() / "self.vtu";
    writeGrids(in, {grid});
    ASSERT_EQ(runCli("encode " + in.string() + " -o " + enc.string()).exitCode, 0);
    const auto r = runCli("diff " + in.string() + " " + enc.string() + " -o " + out.string() + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_TRUE(report["identical"].get<bool>());
    const auto& g = report["grids"][0];
    EXPECT_EQ(count(g, "same"), grid->activeVoxelCount());
    EXPECT_EQ(count(g, "value_differs") + count(g, "only_in_a") + count(g, "only_in_b"), 0u);
    EXPECT_EQ(g["max_abs_error"].get<double>(), 0.0);
    auto ug = readVtu(out);
    ASSERT_EQ(uint64_t(ug->GetNumberOfCells()), grid->tree().activeLeafVoxelCount() + 1);  // the tile is one cell
    vtkDataArray* status = ug->GetCellData()->GetArray("status");
    vtkDataArray* a = ug->GetCellData()->GetArray("a");
    vtkDataArray* b = ug->GetCellData()->GetArray("b");
    ASSERT_TRUE(status && a && b);
    for (vtkIdType c = 0; c < ug->GetNumberOfCells(); ++c) {
        const openvdb::Coord ijk = cellVoxels(ug, c, grid->transform()).min();
        EXPECT_EQ(status->GetTuple1(c), 0.0);
        EXPECT_EQ(float(a->GetTuple1(c)), grid->tree().getValue(ijk));
        EXPECT_EQ(float(b->GetTuple1(c)), grid->tree().getValue(ijk));
    }
}

TEST(VtkDiff, LossyDecodeShowsTheEncodersMaxError) {
    auto grid = ball("lossy");
    const double bound = 0.01;
    const fs::path in = workDir() / "lossy.vdb", enc = workDir() / "lossy.ssvdag", dec = workDir() / "lossy_decoded.vdb", out = workDir() / "lossy.vtu";
    writeGrids(in, {grid});
    auto r = runCli("encode " + in.string() + " -o " + enc.string() + " --abs-error " + std::to_string(bound) + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const double encoderMax = nlohmann::json::parse(r.out)["grids_lossy"][0]["max_abs_error"].get<double>();
    ASSERT_GT(encoderMax, 0.0);
    ASSERT_EQ(runCli("decode " + enc.string() + " -o " + dec.string()).exitCode, 0);

    r = runCli("diff " + in.string() + " " + dec.string() + " -o " + out.string() + " --json");
    EXPECT_EQ(r.exitCode, 1) << "a lossy decode differs";
    const auto report = nlohmann::json::parse(r.out);
    const auto& g = report["grids"][0];
    EXPECT_DOUBLE_EQ(g["max_abs_error"].get<double>(), encoderMax);
    EXPECT_LE(g["max_abs_error"].get<double>(), bound);
    EXPECT_EQ(count(g, "only_in_a") + count(g, "only_in_b"), 0u);

    // Independent count of differing values, and each cell against OpenVDB.
    auto decoded = openvdb::gridPtrCast<openvdb::FloatGrid>(readGrids(dec)->front());
    uint64_t differing = 0;
    double maxError = 0;
    for (auto it = grid->cbeginValueOn(); it; ++it) {
        const float b = decoded->tree().getValue(it.getCoord());
        if (std::memcmp(&b, &*it, sizeof(float)) != 0) differing += it.getVoxelCount();
        maxError = std::max(maxError, std::abs(double(*it) - double(b)));
    }
    EXPECT_EQ(count(g, "value_differs"), differing);
    EXPECT_EQ(g["max_abs_error"].get<double>(), maxError);
    auto ug = readVtu(out);
    vtkDataArray* status = ug->GetCellData()->GetArray("status");
    vtkDataArray* a = ug->GetCellData()->GetArray("a");
    vtkDataArray* b = ug->GetCellData()->GetArray("b");
    vtkDataArray* err = ug->GetCellData()->GetArray("abs_error");
    ASSERT_TRUE(status && a && b && err);
    for (vtkIdType c = 0; c < ug->GetNumberOfCells(); ++c) {
        const openvdb::Coord ijk = cellVoxels(ug, c, grid->transform()).min();
        const float va = grid->tree().getValue(ijk), vb = decoded->tree().getValue(ijk);
        EXPECT_EQ(float(a->GetTuple1(c)), va);
        EXPECT_EQ(float(b->GetTuple1(c)), vb);
        EXPECT_EQ(err->GetTuple1(c), std::abs(double(va) - double(vb)));
        EXPECT_EQ(status->GetTuple1(c), std::memcmp(&va, &vb, sizeof(float)) == 0 ? 0.0 : 1.0);
    }
    // The .ssvdag itself compares the same way.
    r = runCli("diff " + in.string() + " " + enc.string() + " --json");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_DOUBLE_EQ(nlohmann::json::parse(r.out)["grids"][0]["max_abs_error"].get<double>(), encoderMax);
}

TEST(VtkDiff, FindsTheOneRemovedVoxel) {
    auto a = ball("cut");
    auto b = a->deepCopy();
    // A voxel of the narrow band, picked by OpenVDB's iterator.
    auto it = a->cbeginValueOn();
    for (int n = 0; n < 1234; ++n) ++it;
    const openvdb::Coord removed = it.getCoord();
    const float value = *it;
    b->tree().setValueOff(removed);
    const fs::path pa = workDir() / "cut_a.vdb", pb = workDir() / "cut_b.vdb", out = workDir() / "cut.vtu";
    writeGrids(pa, {a});
    writeGrids(pb, {b});
    auto r = runCli("diff " + pa.string() + " " + pb.string() + " -o " + out.string() + " --only-differences --json");
    EXPECT_EQ(r.exitCode, 1) << r.err;
    const nlohmann::json g = nlohmann::json::parse(r.out)["grids"][0];
    EXPECT_EQ(count(g, "only_in_a"), 1u);
    EXPECT_EQ(count(g, "only_in_b") + count(g, "value_differs"), 0u);
    EXPECT_EQ(count(g, "same"), a->activeVoxelCount() - 1);
    auto ug = readVtu(out);
    ASSERT_EQ(ug->GetNumberOfCells(), 1);
    const openvdb::CoordBBox cell = cellVoxels(ug, 0, a->transform());
    EXPECT_EQ(cell.min(), removed);
    EXPECT_EQ(cell.max(), removed);
    EXPECT_EQ(ug->GetCellData()->GetArray("status")->GetTuple1(0), 2.0);
    EXPECT_EQ(float(ug->GetCellData()->GetArray("a")->GetTuple1(0)), value);
    EXPECT_TRUE(std::isnan(ug->GetCellData()->GetArray("b")->GetTuple1(0)));
    // The other way round it is only in B; without -o nothing is written.
    r = runCli("diff " + pb.string() + " " + pa.string() + " --json");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(count(nlohmann::json::parse(r.out)["grids"][0], "only_in_b"), 1u);
}

TEST(VtkDiff, TileAgainstALeafIsComparedVoxelByVoxel) {
    auto a = ball("tiles");
    auto b = a->deepCopy();
    b->tree().setValueOn(openvdb::Coord(65, 1, 1), 9.0f);  // splits B's tile into a leaf
    ASSERT_EQ(b->tree().activeTileCount(), 0u);
    const fs::path pa = workDir() / "tile_a.vdb", pb = workDir() / "tile_b.vdb";
    writeGrids(pa, {a});
    writeGrids(pb, {b});
    const auto r = runCli("diff " + pa.string() + " " + pb.string() + " --json");
    EXPECT_EQ(r.exitCode, 1);
    const nlohmann::json g = nlohmann::json::parse(r.out)["grids"][0];
    EXPECT_EQ(count(g, "value_differs"), 1u);
    EXPECT_EQ(count(g, "same"), a->activeVoxelCount() - 1);
    EXPECT_DOUBLE_EQ(g["max_abs_error"].get<double>(), 1.5);
}

TEST(VtkDiff, MismatchedInputsAreReported) {
    auto a = ball("x");
    auto other = openvdb::DoubleGrid::create();
    other->setName("x");
    other->tree().setValueOn(openvdb::Coord(0), 1.0);
    const fs::path pa = workDir() / "mm_a.vdb", pb = workDir() / "mm_b.vdb", pc = workDir() / "mm_c.vdb";
    writeGrids(pa, {a});
    writeGrids(pb, {other});
    writeGrids(pc, {a, a->deepCopy()});
    auto r = runCli("diff " + pa.string() + " " + pb.string());
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("same type"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    r = runCli("diff " + pa.string() + " " + pc.string() + " --json");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_FALSE(nlohmann::json::parse(r.out)["header_differences"].empty());
    r = runCli("diff " + pa.string() + " " + (workDir() / "none.vdb").string());
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("none.vdb"), std::string::npos) << r.err;
}

TEST(VtkDiff, BitExactStatusNaNsSignedZerosAndVectors) {
    openvdb::initialize();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    auto a = openvdb::FloatGrid::create(0.0f);
    a->setName("s");
    a->tree().setValueOn(openvdb::Coord(0, 0, 0), nan);
    a->tree().setValueOn(openvdb::Coord(1, 0, 0), 0.0f);
    a->tree().setValueOn(openvdb::Coord(2, 0, 0), 3.0f);
    auto b = a->deepCopy();
    b->tree().setValueOn(openvdb::Coord(1, 0, 0), -0.0f);  // equal as numbers, not as bits
    b->tree().setValueOn(openvdb::Coord(2, 0, 0), nan);     // a non-finite error
    auto va = openvdb::Vec3SGrid::create();
    va->setName("v");
    va->tree().setValueOn(openvdb::Coord(5, 5, 5), openvdb::Vec3s(1, 2, 3));
    va->tree().setValueOn(openvdb::Coord(6, 5, 5), openvdb::Vec3s(0, 0, 0));
    auto vb = va->deepCopy();
    vb->tree().setValueOn(openvdb::Coord(5, 5, 5), openvdb::Vec3s(4, 6, 3));  // |(3,4,0)| = 5
    const fs::path pa = workDir() / "bits_a.vdb", pb = workDir() / "bits_b.vdb", out = workDir() / "bits.vtm";
    writeGrids(pa, {a, va});
    writeGrids(pb, {b, vb});
    const auto r = runCli("diff " + pa.string() + " " + pb.string() + " -o " + out.string() + " --json");
    EXPECT_EQ(r.exitCode, 1) << r.err;
    const auto report = nlohmann::json::parse(r.out);
    const nlohmann::json* s = nullptr;
    const nlohmann::json* v = nullptr;
    for (const auto& g : report["grids"]) (g["name"] == "s" ? s : v) = &g;
    ASSERT_TRUE(s && v);
    EXPECT_EQ(count(*s, "same"), 1u);           // NaN against the same NaN
    EXPECT_EQ(count(*s, "value_differs"), 2u);  // 0 vs -0, 3 vs NaN
    EXPECT_EQ((*s)["non_finite_errors"].get<uint64_t>(), 1u);
    EXPECT_EQ((*s)["max_abs_error"].get<double>(), 0.0);
    EXPECT_EQ(count(*v, "value_differs"), 1u);
    EXPECT_DOUBLE_EQ((*v)["max_abs_error"].get<double>(), 5.0);
    auto blocks = readVtm(out);
    ASSERT_EQ(blocks->GetNumberOfBlocks(), 2u);
    for (unsigned i = 0; i < 2; ++i) {
        auto* ug = vtkUnstructuredGrid::SafeDownCast(blocks->GetBlock(i));
        ASSERT_NE(ug, nullptr);
        if (blockName(blocks, i) != "v") continue;
        vtkDataArray* a3 = ug->GetCellData()->GetArray("a");
        ASSERT_EQ(a3->GetNumberOfComponents(), 3);
        for (vtkIdType c = 0; c < ug->GetNumberOfCells(); ++c) {
            const openvdb::Coord ijk = cellVoxels(ug, c, va->transform()).min();
            for (int k = 0; k < 3; ++k) EXPECT_EQ(a3->GetComponent(c, k), double(va->tree().getValue(ijk)[k]));
            EXPECT_DOUBLE_EQ(ug->GetCellData()->GetArray("abs_error")->GetTuple1(c), ijk == openvdb::Coord(5, 5, 5) ? 5.0 : 0.0);
        }
    }
}
