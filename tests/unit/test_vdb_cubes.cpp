// The .vdb file read region by region (vdb_bridge/VdbCubes.h) and encoded
// cube by cube must give the very bytes of the whole-file import encoded in
// memory, for every shared data file, every grid type, tiles at every
// level, inactive values, half floats and every codec; the decoded file is
// compared with the input by OpenVDB's own accessors (compareWithFile). The
// CLI's --memory-limit and --threads must not change the output either.
#include <algorithm>
#include <cstring>
#include <set>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "tests/unit/BuildPaths.h"
#include "src/format/SsvdagFile.h"
#include "tests/unit/TestInputs.h"
#include "src/pipeline/CubeEncoder.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "tests/unit/CliRunner.h"
#include "vdb_bridge/VdbCompare.h"
#include "vdb_bridge/VdbCubes.h"
#include "vdb_bridge/VdbImport.h"

using namespace vdbdag;
namespace fs = std::filesystem;

namespace {

fs::path tempDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_cubes_" + std::to_string(getpid()));
        fs::remove_all(d);  // a finished process with the same PID may have left it
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

std::vector<uint8_t> inMemoryFile(const fs::path& path, const bridge::ImportOptions& import = {}, const pipeline::EncodeOptions& options = {}) {
    return format::writeScene(pipeline::encodeVolume(bridge::importVdb(path.string(), import).volume, options));
}

std::vector<uint8_t> byCubesFile(const fs::path& path, std::optional<unsigned> cubeLog2, const bridge::ImportOptions& import = {},
                                 const pipeline::EncodeOptions& options = {}) {
    bridge::VdbCubeInput input = bridge::openVdbCubes(path.string(), import);
    pipeline::CubeBudget budget;
    budget.cubeLog2 = cubeLog2;
    return format::writeScene(pipeline::encodeSourcesByCubes(std::move(input.grids), input.fileMetadata, options, budget));
}

// Every supported type; tiles at all three levels; level-set-like inactive
// values; saved with `codec` and half floats when asked.
fs::path writeAllTypes(const std::string& name, uint32_t codec, bool half, int seed) {
    openvdb::initialize();
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> small(-200, 200);
    auto f = openvdb::FloatGrid::create(3.0f);
    f->setName("density");
    f->setGridClass(openvdb::GRID_LEVEL_SET);
    auto acc = f->getAccessor();
    for (int i = 0; i < 4000; ++i) {
        const openvdb::Coord c(small(rng), small(rng), small(rng) / 4);
        acc.setValueOn(c, float(rng() % 9) * 0.25f);
        acc.setValueOff(c.offsetBy(1, 0, 0), -3.0f);  // inactive, not the background
    }
    f->tree().addTile(1, openvdb::Coord(1024, 0, 0), 1.5f, true);
    f->tree().addTile(2, openvdb::Coord(-128 * 20, 128 * 3, 0), 2.5f, true);
    f->tree().addTile(2, openvdb::Coord(128 * 20, 128 * 3, 0), -3.0f, false);  // inactive inside tile
    f->tree().addTile(3, openvdb::Coord(4096 * 3, -4096 * 2, 4096), 4.0f, true);
    f->setSaveFloatAsHalf(half);
    auto d = openvdb::DoubleGrid::create(0.0);
    d->setName("temperature");
    auto i32 = openvdb::Int32Grid::create(0);
    i32->setName("labels");
    auto v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    v->setName("Cd");
    auto b = openvdb::BoolGrid::create(false);
    b->setName("flags");
    auto m = openvdb::MaskGrid::create();
    m->setName("mask");
    for (int i = 0; i < 3000; ++i) {
        const openvdb::Coord c(small(rng), small(rng) / 2, small(rng));
        d->tree().setValueOn(c, double(small(rng)) * 1e-3);
        i32->tree().setValueOn(c.offsetBy(3, 0, 0), c.x() / 16);
        v->tree().setValueOn(c, openvdb::Vec3s(float(rng() % 4), 0.5f, float(c.z())));
        b->tree().setValueOn(c, (rng() & 1) != 0);
        m->tree().setValueOn(c.offsetBy(0, 0, 5));
    }
    i32->tree().addTile(1, openvdb::Coord(512, 512, 512), 7, true);
    m->tree().addTile(2, openvdb::Coord(1024, 1024, 1024), true, true);
    const fs::path path = tempDir() / (name + ".vdb");
    openvdb::io::File file(path.string());
    file.setCompression(codec | openvdb::io::COMPRESS_ACTIVE_MASK);
    openvdb::MetaMap meta;
    meta.insertMeta("creator", openvdb::StringMetadata("test_vdb_cubes"));
    file.write({f, d, i32, v, b, m}, meta);
    file.close();
    return path;
}

// A level-set sphere (float, float saved as half, or double) with active
// tiles beside its band, for --normals: 8^3 tiles beside leaves whose +y
// face holds active voxels, and a 128^3 tile beside the band's +x end (a
// voxel whose neighbour lies in a tile reads the tile's value). Checks
// with OpenVDB that voxels beside both kinds of tile exist.
template <typename GridT>
fs::path writeSphereBesideTiles(const std::string& name, bool half = false) {
    using V = typename GridT::ValueType;
    openvdb::initialize();
    auto g = openvdb::tools::createLevelSetSphere<GridT>(V(24), openvdb::Vec3f(100.3f, 0.2f, 0.1f), 1.0f, 3.0f);  // the band reaches x = 127
    g->setName("ball");
    auto& tree = g->tree();
    std::vector<openvdb::Coord> beside;
    for (auto leaf = tree.cbeginLeaf(); leaf && beside.size() < 6; ++leaf) {
        const openvdb::Coord o = leaf->origin().offsetBy(0, 8, 0);
        if (tree.probeConstLeaf(o) || tree.isValueOn(o) || std::find(beside.begin(), beside.end(), o) != beside.end()) continue;
        bool onFace = false;
        for (int x = 0; x < 8; ++x)
            for (int z = 0; z < 8; ++z) onFace = onFace || leaf->isValueOn(leaf->origin().offsetBy(x, 7, z));
        if (onFace) beside.push_back(o);
    }
    for (size_t i = 0; i < beside.size(); ++i) tree.addTile(1, beside[i], V(0.25 * double(i)), true);
    tree.addTile(2, openvdb::Coord(128, 0, 0), V(-0.5), true);
    int besideSmall = 0, besideLarge = 0;
    for (auto v = tree.cbeginLeaf(); v; ++v)
        for (auto on = v->cbeginValueOn(); on; ++on) {
            const openvdb::Coord c = on.getCoord();
            besideSmall += tree.isValueOn(c.offsetBy(0, 1, 0)) && !tree.probeConstLeaf(c.offsetBy(0, 1, 0)) && c.x() < 128;
            besideLarge += c.x() == 127 && c.y() >= 0 && c.z() >= 0;
        }
    EXPECT_GT(besideSmall, 0) << "no voxel beside an 8^3 tile";
    EXPECT_GT(besideLarge, 0) << "no voxel beside the 128^3 tile";
    g->setSaveFloatAsHalf(half);
    const fs::path path = tempDir() / (name + ".vdb");
    openvdb::io::File(path.string()).write({g});
    return path;
}

} // namespace

TEST(VdbCubes, EveryTypeCodecAndCubeSizeGivesTheInMemoryBytes) {
    const uint32_t codecs[3] = {openvdb::io::COMPRESS_BLOSC, openvdb::io::COMPRESS_ZIP, openvdb::io::COMPRESS_NONE};
    for (int k = 0; k < 3; ++k) {
        const fs::path path = writeAllTypes("all_types_" + std::to_string(k), codecs[k], k == 1, 10 + k);
        SCOPED_TRACE(path.string());
        const std::vector<uint8_t> whole = inMemoryFile(path);
        for (unsigned cube : {3u, 5u, 8u, 13u}) EXPECT_EQ(byCubesFile(path, cube), whole) << "cubes of 2^" << cube;
        EXPECT_EQ(byCubesFile(path, std::nullopt), whole) << "default budget";
        // The decoded cube-by-cube file is the input, by OpenVDB's accessors.
        const fs::path encoded = tempDir() / (path.stem().string() + ".ssvdag");
        std::ofstream(encoded, std::ios::binary).write(reinterpret_cast<const char*>(whole.data()), std::streamsize(whole.size()));
        const auto result = bridge::compareWithFile(path.string(), pipeline::decodeScene(format::readSceneFile(encoded.string())));
        EXPECT_TRUE(result.identical) << result.headerDifferences.size() << " header, " << result.topology.size() << " topology, " << result.values.size() << " value differences";
    }
}

TEST(VdbCubes, TopologyOnlyAndChosenGridsGiveTheInMemoryBytes) {
    const fs::path path = writeAllTypes("all_types_topology", openvdb::io::COMPRESS_BLOSC, false, 3);
    bridge::ImportOptions topology;
    topology.topologyOnly = true;
    EXPECT_EQ(byCubesFile(path, 4, topology), inMemoryFile(path, topology));
    bridge::ImportOptions some;
    some.onlyGrids = {"labels", "density"};
    EXPECT_EQ(byCubesFile(path, 6, some), inMemoryFile(path, some));
    bridge::ImportOptions unknown;
    unknown.onlyGrids = {"nope"};
    try {
        bridge::openVdbCubes(path.string(), unknown);
        ADD_FAILURE() << "an unknown grid name must be refused";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("no grid named 'nope'"), std::string::npos) << e.what();
    }
}

TEST(VdbCubes, EverySharedDataFileGivesTheInMemoryBytes) {
    const auto files = vdbdag::testing::sharedVdbFiles();
    if (files.empty()) GTEST_SKIP() << "../shared/data not present";
    pipeline::EncodeOptions options;
    options.computeSvdagStats = true;  // as `encode --svdag-stats` (the extra reduction, on both paths)
    for (const auto& f : files) {
        SCOPED_TRACE(f.string());
        const std::vector<uint8_t> whole = inMemoryFile(f, {}, options);
        EXPECT_EQ(byCubesFile(f, 5, {}, options), whole);
        EXPECT_EQ(byCubesFile(f, std::nullopt, {}, options), whole);
    }
}

TEST(VdbCubes, CliMemoryLimitAndThreadsDoNotChangeTheBytes) {
    const fs::path in = writeAllTypes("cli_input", openvdb::io::COMPRESS_BLOSC, false, 8);
    const fs::path a = tempDir() / "cli_default.ssvdag", b = tempDir() / "cli_limited.ssvdag", c = tempDir() / "cli_one_thread.ssvdag";
    ASSERT_EQ(vdbdag::testing::runCli("encode " + in.string() + " -o " + a.string() + " -f").exitCode, 0);
    const auto limited = vdbdag::testing::runCli("encode " + in.string() + " -o " + b.string() + " -f --memory-limit 1M --threads 2");
    ASSERT_EQ(limited.exitCode, 0) << limited.err;
    ASSERT_EQ(vdbdag::testing::runCli("encode " + in.string() + " -o " + c.string() + " -f --memory-limit 64K --threads 1").exitCode, 0);
    EXPECT_EQ(vdbdag::testing::runShell("cmp " + a.string() + " " + b.string()).exitCode, 0);
    EXPECT_EQ(vdbdag::testing::runShell("cmp " + a.string() + " " + c.string()).exitCode, 0);
    const auto bad = vdbdag::testing::runCli("encode " + in.string() + " -o " + b.string() + " -f --memory-limit lots");
    EXPECT_NE(bad.exitCode, 0);
    // --normals under --memory-limit: the whole grid's file (the library's
    // import and in-memory encode), a level set with tiles beside its band.
    const fs::path ball = writeSphereBesideTiles<openvdb::FloatGrid>("cli_ball");
    bridge::ImportOptions io;
    io.normals = true;
    pipeline::EncodeOptions withNormals;
    withNormals.normalBits = 16;
    const std::vector<uint8_t> whole = inMemoryFile(ball, io, withNormals);
    for (const std::string limit : {"", " --memory-limit 1M --threads 1"}) {
        const auto normals = vdbdag::testing::runCli("encode " + ball.string() + " -o " + b.string() + " -f --normals 16" + limit);
        ASSERT_EQ(normals.exitCode, 0) << normals.err;
        std::ifstream file(b, std::ios::binary);
        EXPECT_EQ(std::vector<uint8_t>(std::istreambuf_iterator<char>(file), {}), whole) << "--normals 16" << limit;
    }
}

// --normals read region by region: each cube's normals, the gradient with a
// one-voxel halo read back from the scratch file (or a vec3 normal grid's
// values), give the file of the whole-grid import, whose normals
// test_normals checks against OpenVDB's accessor and the closed form:
// across cubes of every size, beside active tiles, for float (also saved
// as half), double and vec3 grids.
TEST(VdbCubes, NormalsAcrossCubesGiveTheInMemoryBytes) {
    const std::vector<fs::path> inputs{writeAllTypes("normals_all", openvdb::io::COMPRESS_BLOSC, false, 31),
                                       writeAllTypes("normals_half", openvdb::io::COMPRESS_ZIP, true, 32),
                                       writeSphereBesideTiles<openvdb::FloatGrid>("normals_ball"),
                                       writeSphereBesideTiles<openvdb::FloatGrid>("normals_ball_half", true),
                                       writeSphereBesideTiles<openvdb::DoubleGrid>("normals_ball_double")};
    pipeline::EncodeOptions options;
    options.normalBits = 16;
    for (size_t k = 0; k < inputs.size(); ++k)
        for (const std::string normalGrid : {"", "Cd"}) {
            const fs::path& path = inputs[k];
            const bool ball = k >= 2;
            if (ball && !normalGrid.empty()) continue;
            SCOPED_TRACE(path.string() + " --normal-grid '" + normalGrid + "'");
            bridge::ImportOptions io;
            io.normals = true;
            io.normalGrid = normalGrid;
            const std::vector<uint8_t> whole = inMemoryFile(path, io, options);
            const auto scene = format::readScene(whole, "whole");
            EXPECT_EQ(std::count_if(scene.grids.begin(), scene.grids.end(), [](const auto& g) { return g.normals.has_value(); }),
                      ball || !normalGrid.empty() ? 1 : 2);
            for (unsigned cube : {3u, 4u, 7u}) EXPECT_EQ(byCubesFile(path, cube, io, options), whole) << "cubes of 2^" << cube;
            EXPECT_EQ(byCubesFile(path, std::nullopt, io, options), whole) << "default budget";
        }
    // The same refusals as the whole-file import; topology only is read whole.
    for (const std::string& normalGrid : {std::string("density"), std::string("missing")}) {
        bridge::ImportOptions io;
        io.normals = true;
        io.normalGrid = normalGrid;
        EXPECT_THROW(bridge::importVdb(inputs[0].string(), io), Error);
        EXPECT_THROW(bridge::openVdbCubes(inputs[0].string(), io), Error) << normalGrid;
    }
    // A missing --grid first, as importVdb checks it (before any grid is read).
    bridge::ImportOptions both;
    both.normals = true;
    both.normalGrid = "density";  // also of the wrong type
    both.onlyGrids = {"density", "missing"};
    for (const bool byCubes : {false, true})
        try {
            if (byCubes) bridge::openVdbCubes(inputs[0].string(), both);
            else bridge::importVdb(inputs[0].string(), both);
            ADD_FAILURE() << "accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("no grid named 'missing'"), std::string::npos) << e.what();
        }
    bridge::ImportOptions topology;
    topology.normals = topology.topologyOnly = true;
    EXPECT_THROW(bridge::openVdbCubes(inputs[0].string(), topology), Error);
}

// mpirun -np 2 and -np 3 of vdbdag-mpi: the same bytes as one process, on a
// generated file and on a shared level set with tiles (bunny fog).
TEST(VdbCubes, MpirunGivesTheSingleProcessBytes) {
#if !defined(VDBDAG_MPI_BINARY)
    GTEST_SKIP() << "vdbdag-mpi not built (no MPI found)";
#else
    std::vector<fs::path> inputs{writeAllTypes("mpi_input", openvdb::io::COMPRESS_BLOSC, false, 21)};
    const fs::path fog = fs::path(VDBDAG_SHARED_DATA) / "levelsets" / "bunny_d512_fog.vdb";
    if (fs::exists(fog)) inputs.push_back(fog);
    for (const fs::path& in : inputs) {
        SCOPED_TRACE(in.string());
        const fs::path single = tempDir() / (in.stem().string() + "_single.ssvdag");
        ASSERT_EQ(vdbdag::testing::runCli("encode " + in.string() + " -o " + single.string() + " -f").exitCode, 0);
        for (int ranks : {2, 3}) {
            const fs::path out = tempDir() / (in.stem().string() + "_np" + std::to_string(ranks) + ".ssvdag");
            const std::string command = std::string(VDBDAG_MPIRUN) + " --oversubscribe --allow-run-as-root -np " + std::to_string(ranks) + " " +
                                        VDBDAG_MPI_BINARY + " encode " + in.string() + " -o " + out.string() + " -f --memory-limit 8M";
            const auto run = vdbdag::testing::runShell(command);
            ASSERT_EQ(run.exitCode, 0) << command << "\n" << run.err;
            EXPECT_EQ(vdbdag::testing::runShell("cmp " + single.string() + " " + out.string()).exitCode, 0) << ranks << " processes";
        }
    }
    // --normals: each process computes the normals of its cubes; the file
    // is the whole grid's (the library's import and in-memory encode).
    const fs::path ball = writeSphereBesideTiles<openvdb::FloatGrid>("mpi_ball"), two = tempDir() / "normals_np2.ssvdag";
    bridge::ImportOptions io;
    io.normals = true;
    pipeline::EncodeOptions withNormals;
    withNormals.normalBits = 12;
    const auto run = vdbdag::testing::runShell(std::string(VDBDAG_MPIRUN) + " --oversubscribe --allow-run-as-root -np 2 " + VDBDAG_MPI_BINARY + " encode " +
                                               ball.string() + " -o " + two.string() + " -f --normals 12 --memory-limit 8M");
    ASSERT_EQ(run.exitCode, 0) << run.err;
    std::ifstream file(two, std::ios::binary);
    EXPECT_EQ(std::vector<uint8_t>(std::istreambuf_iterator<char>(file), {}), inMemoryFile(ball, io, withNormals)) << "--normals, 2 processes";
    // A failing run (an output that is the input) ends every process with an error.
    const auto bad = vdbdag::testing::runShell(std::string(VDBDAG_MPIRUN) + " --oversubscribe --allow-run-as-root -np 2 " + VDBDAG_MPI_BINARY +
                                               " encode " + inputs[0].string() + " -o " + inputs[0].string() + " -f");
    EXPECT_NE(bad.exitCode, 0);
#endif
}

// The summary's "every value the same" (which lets the encoder skip a
// gather pass) against OpenVDB's own iteration of each layer.
TEST(VdbCubes, UniformLayersAreThoseWhoseValuesOpenVdbSeesAllEqual) {
    const fs::path path = writeAllTypes("uniform", openvdb::io::COMPRESS_BLOSC, false, 3);
    bridge::VdbCubeInput input = bridge::openVdbCubes(path.string());
    openvdb::io::File file(path.string());
    file.open();
    for (auto& source : input.grids) {
        if (source->header().valueType != ValueType::Float) continue;
        auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(source->header().name));
        std::set<float> active, inactive;
        for (auto it = grid->tree().cbeginValueOn(); it; ++it) active.insert(*it);
        for (auto it = grid->tree().cbeginValueOff(); it; ++it)
            if (*it != grid->background()) inactive.insert(*it);
        const LayerSummary a = source->summary(Layer::Active), i = source->summary(Layer::Inactive);
        EXPECT_EQ(a.uniform(), active.size() == 1);
        ASSERT_EQ(i.uniform(), inactive.size() == 1);
        ASSERT_TRUE(i.uniform());  // the level-set-like grid: every inactive value is -3
        float value;
        std::memcpy(&value, i.uniformValue.data(), sizeof value);
        EXPECT_EQ(value, *inactive.begin());
    }
}
