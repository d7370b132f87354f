// signedFillInactive (src/volume/SignedFill.h) against OpenVDB's own
// tools::signedFloodFill: grids are flood-filled by OpenVDB, written, read
// back by the importer, and the inactive layer computed from the active
// voxels alone must equal the one the importer read (every inside voxel and
// tile, bit for bit). Random sparse trees over several 4096^3 root nodes
// (so the root's z runs are filled too), OpenVDB's level-set sphere and
// platonic solids, and the shared level sets; a file whose inactive values
// are not a flood fill, and the cases it does not apply to, are told apart.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetPlatonic.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/SignedFloodFill.h>

#include "src/format/SsvdagContainer.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/CubeEncoder.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "src/volume/SignedFill.h"
#include "tests/unit/TestInputs.h"
#include "vdb_bridge/VdbCubes.h"
#include "vdb_bridge/VdbExport.h"
#include "vdb_bridge/VdbImport.h"
#include <vdbdag/vdbdag.h>

namespace fs = std::filesystem;
using namespace vdbdag;

namespace {

fs::path tempFile(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("vdbdag_signed_fill_" + std::to_string(getpid()));
    fs::create_directories(dir);
    return dir / name;
}

GridRecord importOne(const fs::path& path) {
    Volume v = bridge::importVdb(path.string()).volume;
    EXPECT_EQ(v.grids.size(), 1u);
    return std::move(v.grids.at(0));
}

template <typename GridT>
GridRecord roundTrip(const typename GridT::Ptr& grid, const std::string& name) {
    const fs::path path = tempFile(name + ".vdb");
    openvdb::io::File(path.string()).write({grid});
    GridRecord record = importOne(path);
    fs::remove(path);
    return record;
}

// Whether the inactive layer computed from the active voxels is the record's.
::testing::AssertionResult fillMatches(const GridRecord& r) {
    const std::optional<InactiveLayer> fill = signedFillInactive(r.topology, r.values, r.valueType, r.background);
    if (!fill) return ::testing::AssertionFailure() << "not applicable";
    if (!sameInactiveLayer(fill->topology, fill->values, r.inactiveTopology, r.inactiveValues, r.valueType))
        return ::testing::AssertionFailure() << "computed " << fill->topology.bricks.size() << " bricks, " << fill->topology.tiles.size()
                                             << " tiles; the file " << r.inactiveTopology.bricks.size() << " bricks, "
                                             << r.inactiveTopology.tiles.size() << " tiles";
    return ::testing::AssertionSuccess();
}

// A .vdb file encoded cube by cube (as `vdbdag encode` does), under a budget
// whose cubes are 2^cubeLog2 when given.
std::vector<uint8_t> encodeByCubes(const fs::path& path, std::optional<unsigned> cubeLog2 = std::nullopt) {
    bridge::VdbCubeInput input = bridge::openVdbCubes(path.string());
    pipeline::CubeBudget budget;
    budget.cubeLog2 = cubeLog2;
    return format::writeScene(pipeline::encodeSourcesByCubes(std::move(input.grids), input.fileMetadata, {}, budget));
}

// `grid` written alone to a .vdb file in the test's folder.
fs::path writeVdb(const openvdb::FloatGrid::Ptr& grid, const std::string& name) {
    const fs::path path = tempFile(name + ".vdb");
    openvdb::io::File(path.string()).write({grid});
    return path;
}

// The container version of an .ssvdag file (the u32 after the magic).
uint32_t containerVersion(const std::vector<uint8_t>& file) {
    uint32_t version = 0;
    std::memcpy(&version, file.data() + 8, 4);
    return version;
}

bool hasSection(const std::vector<uint8_t>& file, format::SectionKind kind) {
    for (const format::Section& s : format::readContainer(file, "test", true))
        if (s.kind == kind) return true;
    return false;
}

// Every value of `b` (active or not, voxels and tiles) as OpenVDB gives it,
// against `a`'s.
::testing::AssertionResult sameTrees(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b) {
    auto i = a.tree().cbeginValueAll();
    auto j = b.tree().cbeginValueAll();
    for (; i && j; ++i, ++j) {
        if (i.getBoundingBox() != j.getBoundingBox() || i.isValueOn() != j.isValueOn() || std::memcmp(&*i, &*j, sizeof(float)) != 0)
            return ::testing::AssertionFailure() << "differ at " << i.getCoord() << " / " << j.getCoord();
    }
    if (i || j) return ::testing::AssertionFailure() << "one tree has more values";
    if (a.tree().leafCount() != b.tree().leafCount()) return ::testing::AssertionFailure() << "leaf counts differ";
    return ::testing::AssertionSuccess();
}

// A sparse tree of random signed voxels: clusters in several leaves, 128^3
// nodes and 4096^3 nodes (some along one z column, with gaps between them),
// flood-filled by OpenVDB.
template <typename GridT>
typename GridT::Ptr randomFilledGrid(std::mt19937& rng, double background) {
    using ValueT = typename GridT::ValueType;
    auto grid = GridT::create(ValueT(background));
    auto acc = grid->getAccessor();
    std::uniform_int_distribution<int> small(-40, 40), pick(0, 5);
    std::bernoulli_distribution negative(0.5);
    const int columns[][3] = {{0, 0, 0}, {0, 0, 3 * 4096}, {0, 0, 7 * 4096}, {-4096, 0, 4096}, {0, -2 * 4096, -4096}, {4096, 4096, 0}};
    for (int cluster = 0; cluster < 12; ++cluster) {
        const int* c = columns[pick(rng)];
        const bool inside = negative(rng);
        for (int k = 0; k < 300; ++k) {
            const openvdb::Coord ijk(c[0] + small(rng), c[1] + small(rng), c[2] + small(rng));
            const bool sign = negative(rng) ? inside : !inside;
            acc.setValueOn(ijk, ValueT(sign ? -0.5 : 0.5) * ValueT(1 + k % 3));
        }
    }
    openvdb::tools::signedFloodFill(grid->tree());
    return grid;
}

} // namespace

TEST(SignedFill, RandomTreesOverSeveralRootNodesMatchOpenVdb) {
    openvdb::initialize();
    std::mt19937 rng(2026);
    for (int trial = 0; trial < 6; ++trial) {
        SCOPED_TRACE(trial);
        if (trial % 3 == 2) EXPECT_TRUE(fillMatches(roundTrip<openvdb::DoubleGrid>(randomFilledGrid<openvdb::DoubleGrid>(rng, 1.5), "d")));
        else EXPECT_TRUE(fillMatches(roundTrip<openvdb::FloatGrid>(randomFilledGrid<openvdb::FloatGrid>(rng, 0.25 + trial), "f")));
    }
}

TEST(SignedFill, RootTilesBetweenInsideNodesMatchOpenVdb) {
    // Two inside blocks 4 root nodes apart along z: OpenVDB inserts three
    // inside 4096^3 tiles between them (and none where a face is outside).
    openvdb::initialize();
    auto grid = openvdb::FloatGrid::create(2.0f);
    auto acc = grid->getAccessor();
    for (int z : {4090, 4095, 4 * 4096, 4 * 4096 + 5})
        for (int x = 0; x < 3; ++x) acc.setValueOn(openvdb::Coord(x, 0, z), -1.0f);
    acc.setValueOn(openvdb::Coord(0, 4096, 4095), 1.0f);  // an outside face: no tiles in this column
    acc.setValueOn(openvdb::Coord(0, 4096, 3 * 4096), -1.0f);
    openvdb::tools::signedFloodFill(grid->tree());
    const GridRecord r = roundTrip<openvdb::FloatGrid>(grid, "root");
    size_t rootTiles = 0;
    for (const Tile& t : r.inactiveTopology.tiles) rootTiles += t.log2Size == 12;
    EXPECT_EQ(rootTiles, 3u);
    EXPECT_TRUE(fillMatches(r));
}

TEST(SignedFill, OpenVdbLevelSetsMatch) {
    openvdb::initialize();
    EXPECT_TRUE(fillMatches(roundTrip<openvdb::FloatGrid>(openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(30.0f, {1.5f, -2.f, 0.f}, 0.5f, 3.f),
                                                          "sphere")));
    EXPECT_TRUE(fillMatches(roundTrip<openvdb::FloatGrid>(openvdb::tools::createLevelSetDodecahedron<openvdb::FloatGrid>(12.f, {}, 0.25f, 3.f),
                                                          "dodecahedron")));
    EXPECT_TRUE(fillMatches(roundTrip<openvdb::DoubleGrid>(openvdb::tools::createLevelSetSphere<openvdb::DoubleGrid>(20.0, {}, 0.5, 2.0),
                                                           "dsphere")));
}

TEST(SignedFill, SharedLevelSets) {
    // The shared files whose inactive values are OpenVDB's flood fill (read
    // with pyopenvdb: mapOff(background) then signedFloodFill gives them
    // back), and one whose inside values are something else.
    int seen = 0;
    for (const fs::path& p : vdbdag::testing::sharedVdbFiles()) {
        const std::string name = p.filename().string();
        const bool filled = name == "bunny_d512_ls.vdb" || name == "armadillo_d512_ls.vdb" || name == "ls_sphere.vdb" || name == "ls_cube.vdb";
        if (!filled && name != "unnamed_ls_bg5.vdb") continue;
        SCOPED_TRACE(name);
        ++seen;
        const GridRecord r = importOne(p);
        if (filled) EXPECT_TRUE(fillMatches(r));
        else EXPECT_FALSE(fillMatches(r));
    }
    if (seen == 0) GTEST_SKIP() << "../shared/data absent";
}

TEST(SignedFill, DoesNotApplyWhereTheFillCannotHold) {
    GridTopology active;
    active.bricks.push_back({0, 0, 0, 1});
    LayerValues values;
    const float minusOne = -1.0f;
    values.bricks.resize(4);
    std::memcpy(values.bricks.data(), &minusOne, 4);
    const auto bytes = [](float f) {
        std::vector<uint8_t> b(4);
        std::memcpy(b.data(), &f, 4);
        return b;
    };
    EXPECT_TRUE(signedFillInactive(active, values, ValueType::Float, bytes(3.0f)).has_value());
    EXPECT_FALSE(signedFillInactive(active, values, ValueType::Float, bytes(-3.0f)).has_value());  // a negative background
    EXPECT_FALSE(signedFillInactive(active, values, ValueType::Float, bytes(0.0f)).has_value());
    EXPECT_FALSE(signedFillInactive(active, values, ValueType::Float, bytes(std::numeric_limits<float>::quiet_NaN())).has_value());
    EXPECT_FALSE(signedFillInactive(active, values, ValueType::Int32, bytes(3.0f)).has_value());  // not a float grid
    GridTopology withTile = active;
    withTile.tiles.push_back({8, 0, 0, 3});
    LayerValues tileValues = values;
    tileValues.tiles = bytes(-1.0f);
    EXPECT_FALSE(signedFillInactive(withTile, tileValues, ValueType::Float, bytes(3.0f)).has_value());  // the fill would overwrite it
    // One inside voxel at the leaf's first index: the leaf's other 511
    // voxels are inside too, as one z column after another inherits it.
    const auto fill = signedFillInactive(active, values, ValueType::Float, bytes(3.0f));
    ASSERT_TRUE(fill);
    uint64_t inside = 0;
    for (const Brick& b : fill->topology.bricks) inside += uint64_t(std::popcount(b.mask));
    EXPECT_EQ(inside, 511u);
}

TEST(SignedFill, ALevelSetFileStoresNoInactiveLayerAndReadsBackExactly) {
    openvdb::initialize();
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(40.0f, {0.5f, 3.f, -2.f}, 0.5f, 3.f);
    sphere->setName("sphere");
    const fs::path in = writeVdb(sphere, "sphere_in");
    const std::vector<uint8_t> file = encodeByCubes(in);
    // An InactiveSignedFill section instead of the inactive layer's, in a
    // version 2 container (which earlier readers refuse).
    EXPECT_TRUE(hasSection(file, format::SectionKind::InactiveSignedFill));
    EXPECT_FALSE(hasSection(file, format::SectionKind::InactiveLevels));
    EXPECT_EQ(containerVersion(file), 2u);
    // The same bytes in small cubes.
    EXPECT_EQ(encodeByCubes(in, 5u), file);
    // Decoded, every value OpenVDB holds is the original's.
    const Volume back = pipeline::decodeScene(format::readScene(file, "sphere"));
    ASSERT_EQ(back.grids.size(), 1u);
    const GridRecord original = importOne(in);
    EXPECT_TRUE(sameInactiveLayer(back.grids[0].inactiveTopology, back.grids[0].inactiveValues, original.inactiveTopology, original.inactiveValues,
                                  ValueType::Float));
    const fs::path out = tempFile("sphere_out.vdb");
    bridge::exportVdb(back, out.string());
    openvdb::io::File f(out.string());
    f.open();
    const auto decoded = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid("sphere"));
    f.close();
    EXPECT_TRUE(sameTrees(*sphere, *decoded));
    // Read without the inside's DAG (a .vdb decode), the fill is made from
    // the decoded active voxels: the same layer.
    format::ReadOptions noLayer;
    noLayer.signedFillLayer = false;
    const format::SsvdagScene bare = format::readScene(file, "sphere", noLayer);
    EXPECT_TRUE(bare.grids[0].inactive.dag.empty());
    const Volume filled = pipeline::decodeScene(bare);
    EXPECT_TRUE(sameInactiveLayer(filled.grids[0].inactiveTopology, filled.grids[0].inactiveValues, original.inactiveTopology,
                                  original.inactiveValues, ValueType::Float));
    // The reader library answers inside voxels with -background, as OpenVDB does.
    const fs::path ssvdag = tempFile("sphere.ssvdag");
    {
        std::ofstream o(ssvdag, std::ios::binary);
        o.write(reinterpret_cast<const char*>(file.data()), std::streamsize(file.size()));
    }
    const vdbdag::File reader = vdbdag::File::open(ssvdag.string());
    vdbdag::Accessor acc = reader.grid(0).accessor();
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> c(-100, 100);  // inside (tiles and voxels), the band and outside
    const auto vdb = sphere->getConstAccessor();
    for (int k = 0; k < 20000; ++k) {
        const openvdb::Coord ijk(c(rng), c(rng), c(rng));
        ASSERT_EQ(acc.value<float>(ijk.x(), ijk.y(), ijk.z()), vdb.getValue(ijk)) << ijk;
    }
    for (const fs::path& p : {in, out, ssvdag}) fs::remove(p);
}

TEST(SignedFill, OtherInactiveValuesKeepTheirLayer) {
    // One inside voxel changed: the fill no longer gives the file's values,
    // so the inactive layer is stored (version 1) and reads back exactly.
    openvdb::initialize();
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(20.0f, {}, 0.5f, 3.f);
    sphere->setName("sphere");
    sphere->tree().setValueOff(openvdb::Coord(0, 0, 0), -2.0f);
    const fs::path in = writeVdb(sphere, "changed");
    const std::vector<uint8_t> file = encodeByCubes(in);
    EXPECT_FALSE(hasSection(file, format::SectionKind::InactiveSignedFill));
    EXPECT_TRUE(hasSection(file, format::SectionKind::InactiveLevels));
    EXPECT_EQ(containerVersion(file), format::kFormatVersion);
    const Volume back = pipeline::decodeScene(format::readScene(file, "changed"));
    const GridRecord original = importOne(in);
    EXPECT_TRUE(sameInactiveLayer(back.grids[0].inactiveTopology, back.grids[0].inactiveValues, original.inactiveTopology, original.inactiveValues,
                                  ValueType::Float));
    fs::remove(in);
}

TEST(SignedFill, ForgedFlagsAreRefused) {
    openvdb::initialize();
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(12.0f, {}, 0.5f, 3.f);
    const fs::path in = writeVdb(sphere, "forged");
    std::vector<format::Section> sections = format::readContainer(encodeByCubes(in), "forged", true);
    fs::remove(in);
    const auto refused = [](const std::vector<format::Section>& s, const std::string& why, bool layer = true) {
        try {
            format::ReadOptions options;
            options.signedFillLayer = layer;
            pipeline::decodeScene(format::readScene(format::writeContainer(s), "forged", options));
        } catch (const Error& e) {
            return std::string(e.what()).find(why) != std::string::npos ? ::testing::AssertionSuccess()
                                                                         : ::testing::AssertionFailure() << "refused for " << e.what();
        }
        return ::testing::AssertionFailure() << "read";
    };
    // A fill section beside an inactive layer.
    std::vector<format::Section> both = sections;
    both.push_back({format::SectionKind::InactiveLevels, 0, {1, 2, 3}});
    EXPECT_TRUE(refused(both, "beside its signed fill"));
    // Another fill.
    std::vector<format::Section> other = sections;
    for (format::Section& s : other)
        if (s.kind == format::SectionKind::InactiveSignedFill) s.data = {1};
    EXPECT_TRUE(refused(other, "unknown fill"));
    // An inactive voxel count the fill does not give (GridInfo's last u64).
    std::vector<format::Section> count = sections;
    for (format::Section& s : count)
        if (s.kind == format::SectionKind::GridInfo) s.data[s.data.size() - 1] ^= 0x40;
    EXPECT_TRUE(refused(count, "the signed fill gives"));
    // The same when the decode makes the fill (ReadOptions::signedFillLayer off).
    EXPECT_TRUE(refused(count, "the signed fill gives", false));
}
