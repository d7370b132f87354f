// .vdb -> .ssvdag -> .vdb round trips, checked by an independent comparison
// written here with OpenVDB alone (topologyDifference both ways, tiles
// counted as their voxels; names, classes, transforms), on the real data in
// ../shared/data (skipped when absent), the generated samples, and random
// OpenVDB grids with tiles at every level and voxels at the int32 extremes.
#include <gtest/gtest.h>

#include <filesystem>
#include <cstring>
#include <random>

#include <openvdb/openvdb.h>
#include <tbb/global_control.h>

#include "tests/unit/BuildPaths.h"
#include "src/format/SsvdagFile.h"
#include "tests/unit/TestInputs.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "vdb_bridge/VdbCompare.h"
#include "vdb_bridge/VdbExport.h"
#include "vdb_bridge/VdbImport.h"

namespace fs = std::filesystem;
using namespace vdbdag;

namespace {

fs::path tempDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_roundtrip_" + std::to_string(getpid()));
        fs::remove_all(d);  // a finished process with the same PID may have left it
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

openvdb::GridPtrVec readGrids(const fs::path& path) {
    openvdb::initialize();
    openvdb::io::File file(path.string());
    file.open(false);
    auto grids = file.getGrids();
    file.close();
    return *grids;
}

template <typename TreeT>
openvdb::MaskTree maskOf(const TreeT& tree) { return openvdb::MaskTree(tree, false, openvdb::TopologyCopy()); }

openvdb::MaskTree maskOfAny(const openvdb::GridBase& g) {
    if (auto p = dynamic_cast<const openvdb::FloatGrid*>(&g)) return maskOf(p->tree());
    if (auto p = dynamic_cast<const openvdb::DoubleGrid*>(&g)) return maskOf(p->tree());
    if (auto p = dynamic_cast<const openvdb::Int32Grid*>(&g)) return maskOf(p->tree());
    if (auto p = dynamic_cast<const openvdb::Int64Grid*>(&g)) return maskOf(p->tree());
    if (auto p = dynamic_cast<const openvdb::BoolGrid*>(&g)) return maskOf(p->tree());
    if (auto p = dynamic_cast<const openvdb::MaskGrid*>(&g)) return maskOf(p->tree());
    if (auto p = dynamic_cast<const openvdb::Vec3SGrid*>(&g)) return maskOf(p->tree());
    if (auto p = dynamic_cast<const openvdb::Vec3DGrid*>(&g)) return maskOf(p->tree());
    if (auto p = dynamic_cast<const openvdb::Vec3IGrid*>(&g)) return maskOf(p->tree());
    ADD_FAILURE() << "unexpected grid type " << g.type();
    return {};
}

template <typename T>
bool sameBits(const T& a, const T& b) {
    if constexpr (std::is_same_v<T, bool>) return a == b;
    else return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Every active value (voxels and tiles) and every value stored in A's leaves
// and tiles, compared bit for bit with B through B's accessor.
template <typename GridT>
uint64_t valueMismatches(const GridT& a, const GridT& b) {
    uint64_t mismatches = 0;
    auto accB = b.getConstAccessor();
    for (auto it = a.cbeginValueAll(); it; ++it) {
        const bool isBackgroundTile = it.isTileValue() && !it.isValueOn() && sameBits(typename GridT::ValueType(*it), a.background());
        if (isBackgroundTile) continue;
        if (!sameBits(typename GridT::ValueType(*it), typename GridT::ValueType(accB.getValue(it.getCoord())))) ++mismatches;
    }
    return mismatches;
}

uint64_t valueMismatchesAny(const openvdb::GridBase& a, const openvdb::GridBase& b) {
    if (a.type() != b.type()) return ~uint64_t(0);
#define VDBDAG_CASE(G) \
    if (auto p = dynamic_cast<const G*>(&a)) return valueMismatches(*p, static_cast<const G&>(b)) + valueMismatches(static_cast<const G&>(b), *p);
    VDBDAG_CASE(openvdb::FloatGrid) VDBDAG_CASE(openvdb::DoubleGrid) VDBDAG_CASE(openvdb::Int32Grid) VDBDAG_CASE(openvdb::Int64Grid)
    VDBDAG_CASE(openvdb::BoolGrid) VDBDAG_CASE(openvdb::Vec3SGrid) VDBDAG_CASE(openvdb::Vec3DGrid) VDBDAG_CASE(openvdb::Vec3IGrid)
#undef VDBDAG_CASE
    return 0;  // mask grids: no values
}

// The independent check: same grids, same headers, same active voxels,
// bit-identical active and stored inactive values.
void expectSameTopology(const fs::path& original, const fs::path& decoded) {
    const auto a = readGrids(original), b = readGrids(decoded);
    ASSERT_EQ(a.size(), b.size()) << original;
    for (size_t g = 0; g < a.size(); ++g) {
        SCOPED_TRACE(original.string() + " grid " + std::to_string(g) + " '" + a[g]->getName() + "'");
        EXPECT_EQ(a[g]->getName(), b[g]->getName());
        EXPECT_EQ(a[g]->getGridClass(), b[g]->getGridClass());
        EXPECT_TRUE(a[g]->transform() == b[g]->transform());
        EXPECT_EQ(bool((*a[g])["name"]), bool((*b[g])["name"])) << "an unnamed grid must stay unnamed";
        const openvdb::MaskTree ma = maskOfAny(*a[g]), mb = maskOfAny(*b[g]);
        openvdb::MaskTree onlyA(ma), onlyB(mb);
        onlyA.topologyDifference(mb);
        onlyB.topologyDifference(ma);
        EXPECT_EQ(onlyA.activeVoxelCount(), 0u);
        EXPECT_EQ(onlyB.activeVoxelCount(), 0u);
        EXPECT_EQ(ma.activeVoxelCount(), mb.activeVoxelCount());
        EXPECT_EQ(a[g]->activeVoxelCount(), b[g]->activeVoxelCount());
        EXPECT_EQ(a[g]->type(), b[g]->type());
        EXPECT_EQ(a[g]->saveFloatAsHalf(), b[g]->saveFloatAsHalf());
        EXPECT_EQ(valueMismatchesAny(*a[g], *b[g]), 0u) << "values differ";
    }
}

// encode -> file -> decode -> file, through the real container and exporter.
fs::path roundTrip(const fs::path& input, bool symmetry = true) {
    const auto imported = bridge::importVdb(input.string());
    pipeline::EncodeOptions options;
    options.symmetry = symmetry;
    const fs::path encoded = tempDir() / (input.stem().string() + (symmetry ? ".ssvdag" : ".svdag"));
    writeFileAtomically(encoded.string(), format::writeScene(pipeline::encodeVolume(imported.volume, options)));
    const fs::path decoded = tempDir() / (input.stem().string() + (symmetry ? "_decoded.vdb" : "_decoded_plain.vdb"));
    bridge::exportVdb(pipeline::decodeScene(format::readSceneFile(encoded.string())), decoded.string());
    return decoded;
}

} // namespace

TEST(VdbRoundTrip, EverySharedDataFileKeepsItsTopology) {
    const auto files = vdbdag::testing::sharedVdbFiles();
    if (files.empty()) GTEST_SKIP() << "../shared/data not present";
    for (const auto& f : files) {
        SCOPED_TRACE(f.string());
        expectSameTopology(f, roundTrip(f, true));
    }
}

TEST(VdbRoundTrip, PlainSvdagAlsoRoundTrips) {
    const fs::path f = fs::path(VDBDAG_SHARED_DATA) / "vdb" / "velocity_tiles.vdb";
    if (!fs::exists(f)) GTEST_SKIP() << f << " not present";
    expectSameTopology(f, roundTrip(f, false));
}

TEST(VdbRoundTrip, PointDataGridIsRefusedWithItsNameUnlessSkipped) {
    const fs::path f = fs::path(VDBDAG_SHARED_DATA) / "vdb" / "points.vdb";
    if (!fs::exists(f)) GTEST_SKIP() << f << " not present";
    try {
        bridge::importVdb(f.string());
        FAIL() << "points.vdb was accepted";
    } catch (const Error& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("PointDataGrid"), std::string::npos) << message;
        EXPECT_NE(message.find("'points'"), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos);
    }
    bridge::ImportOptions options;
    options.skipUnsupported = true;
    const auto result = bridge::importVdb(f.string(), options);
    EXPECT_TRUE(result.volume.grids.empty());
    EXPECT_EQ(result.warnings.size(), 1u);
}

TEST(VdbRoundTrip, GeneratedSamplesKeepTheirTopology) {
    const fs::path dir = tempDir() / "samples";
    ASSERT_EQ(std::system((std::string(VDBDAG_SAMPLES_TOOL) + " " + dir.string() + " > /dev/null").c_str()), 0);
    int count = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        if (e.path().extension() != ".vdb") continue;
        SCOPED_TRACE(e.path().string());
        expectSameTopology(e.path(), roundTrip(e.path()));
        ++count;
    }
    EXPECT_GE(count, 6);
}

TEST(VdbRoundTrip, RandomGridsWithTilesAtEveryLevelAndInt32Extremes) {
    openvdb::initialize();
    std::mt19937 rng(2024);
    const int lo = std::numeric_limits<int32_t>::min(), hi = std::numeric_limits<int32_t>::max();
    for (int trial = 0; trial < 6; ++trial) {
        openvdb::GridPtrVec grids;
        auto g = openvdb::FloatGrid::create(0.5f);
        g->setName("random" + std::to_string(trial));
        auto acc = g->getAccessor();
        std::uniform_int_distribution<int> small(-300, 300);
        for (int i = 0; i < 3000; ++i) acc.setValueOn(openvdb::Coord(small(rng), small(rng), small(rng) / 10), 1.0f);
        // Tiles at every level: 8^3 (level 1), 128^3 (level 2), 4096^3 (root level 3).
        g->tree().addTile(1, openvdb::Coord(1024, 0, 0), 1.0f, true);
        g->tree().addTile(2, openvdb::Coord(-128 * 20, 128 * 3, 0), 1.0f, true);
        if (trial % 2 == 0) g->tree().addTile(3, openvdb::Coord(4096 * 3, -4096 * 2, 4096), 1.0f, true);
        if (trial >= 3) {
            for (int x : {lo, hi})
                for (int y : {lo, hi})
                    for (int z : {lo, hi}) acc.setValueOn(openvdb::Coord(x, y, z), 2.0f);
        }
        grids.push_back(g);
        auto empty = openvdb::MaskGrid::create();
        empty->setName("empty");
        grids.push_back(empty);
        const fs::path in = tempDir() / ("random" + std::to_string(trial) + ".vdb");
        openvdb::io::File file(in.string());
        // Alternate zip, blosc and no compression; half floats in some files.
        const uint32_t codecs[3] = {openvdb::io::COMPRESS_ZIP, openvdb::io::COMPRESS_BLOSC, openvdb::io::COMPRESS_NONE};
        file.setCompression(codecs[trial % 3] | openvdb::io::COMPRESS_ACTIVE_MASK);
        g->setSaveFloatAsHalf(trial % 2 == 1);
        file.write(grids);
        file.close();
        SCOPED_TRACE(in.string());
        const fs::path out = roundTrip(in);
        expectSameTopology(in, out);
        // Tiles stayed tiles: the decoded grid has no more leaves than the input.
        openvdb::io::File back(out.string());
        back.open();
        const auto decoded = openvdb::gridPtrCast<openvdb::FloatGrid>(back.readGrid(g->getName()));
        ASSERT_TRUE(decoded) << "the decoded grid must keep its type";
        back.close();
        EXPECT_LE(decoded->tree().leafCount(), g->tree().leafCount());
        EXPECT_GE(decoded->tree().activeTileCount(), g->tree().activeTileCount());
    }
}

TEST(VdbRoundTrip, HugeActiveTileStaysAHandfulOfNodes) {
    openvdb::initialize();
    auto g = openvdb::MaskGrid::create();
    g->setName("huge");
    g->tree().addTile(3, openvdb::Coord(0, 0, 0), true, true);  // one 4096^3 active tile: 2^36 voxels
    const fs::path in = tempDir() / "huge_tile.vdb";
    openvdb::io::File file(in.string());
    file.write({g});
    file.close();
    const auto imported = bridge::importVdb(in.string());
    ASSERT_EQ(imported.volume.grids.size(), 1u);
    EXPECT_TRUE(imported.volume.grids[0].topology.bricks.empty());
    ASSERT_EQ(imported.volume.grids[0].topology.tiles.size(), 1u);
    EXPECT_EQ(imported.volume.grids[0].topology.tiles[0].log2Size, 12);
    const auto encoded = pipeline::encodeGrid(imported.volume.grids[0]);
    EXPECT_LT(encoded.active.dag.byteSize(), 1024u);
    EXPECT_EQ(encoded.active.voxels, uint64_t(1) << 36);
    const fs::path out = roundTrip(in);
    expectSameTopology(in, out);
    const auto decoded = openvdb::gridPtrCast<openvdb::MaskGrid>(readGrids(out)[0]);
    EXPECT_EQ(decoded->tree().leafCount(), 0u);
    EXPECT_EQ(decoded->tree().activeTileCount(), 1u);
}

TEST(VdbRoundTrip, OutputIsByteIdenticalWhateverTheThreadCount) {
    const fs::path f = fs::path(VDBDAG_SHARED_DATA) / "levelsets" / "armadillo_d512_ls.vdb";
    if (!fs::exists(f)) GTEST_SKIP() << f << " not present";
    // Import each time: the whole path, OpenVDB's stream header included.
    std::vector<uint8_t> one, many;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = format::writeScene(pipeline::encodeVolume(bridge::importVdb(f.string()).volume));
    }
    many = format::writeScene(pipeline::encodeVolume(bridge::importVdb(f.string()).volume));
    EXPECT_EQ(one, many);
}

TEST(VdbRoundTrip, SpecialFloatValuesSurviveBitForBit) {
    openvdb::initialize();
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName("special");
    g->setGridClass(openvdb::GRID_FOG_VOLUME);
    auto acc = g->getAccessor();
    auto fromBits = [](uint32_t bits) { float f; std::memcpy(&f, &bits, 4); return f; };
    const float specials[] = {fromBits(0x7FC00001u),  // quiet NaN with payload
                              fromBits(0x7F800123u),  // signalling NaN with payload
                              fromBits(0xFFC00000u),  // negative NaN
                              -0.0f, fromBits(0x00000001u), fromBits(0x807FFFFFu),  // -0, smallest and largest denormals
                              std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest(), 1.0f, std::nextafter(1.0f, 2.0f)};
    int i = 0;
    for (float v : specials) acc.setValueOn(openvdb::Coord(i++ * 3, -7, 100), v);
    acc.setValueOff(openvdb::Coord(1, -7, 100), -0.0f);                   // inactive -0.0 next to background +0.0
    acc.setValueOff(openvdb::Coord(2, -7, 100), fromBits(0x7FC0BEEFu));  // inactive NaN payload
    g->tree().addTile(1, openvdb::Coord(64, 64, 64), fromBits(0x7FC00042u), true);   // active NaN tile
    g->tree().addTile(1, openvdb::Coord(128, 64, 64), -0.0f, false);                 // inactive -0.0 tile
    auto d = openvdb::DoubleGrid::create(-0.0);
    d->setName("double");
    d->tree().setValueOn(openvdb::Coord(0), std::numeric_limits<double>::denorm_min());
    d->tree().setValueOn(openvdb::Coord(5), -std::numeric_limits<double>::infinity());
    auto v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f, -0.0f, 1.0f));
    v->setName("vec");
    v->tree().setValueOn(openvdb::Coord(-3), openvdb::Vec3s(fromBits(0x7FC00007u), -0.0f, 1e-45f));
    const fs::path in = tempDir() / "special.vdb";
    openvdb::io::File(in.string()).write({g, d, v});
    expectSameTopology(in, roundTrip(in));
}

TEST(VdbRoundTrip, ComparisonDetectsAChangedActiveAndInactiveValue) {
    openvdb::initialize();
    auto g = openvdb::FloatGrid::create(3.0f);
    g->setName("g");
    g->tree().setValueOn(openvdb::Coord(1, 2, 3), 1.0f);
    g->tree().setValueOff(openvdb::Coord(2, 2, 3), -3.0f);
    const fs::path a = tempDir() / "cmp_a.vdb", b = tempDir() / "cmp_b.vdb", c = tempDir() / "cmp_c.vdb";
    openvdb::io::File(a.string()).write({g});
    auto changed = g->deepCopy();
    changed->tree().setValueOn(openvdb::Coord(1, 2, 3), std::nextafter(1.0f, 2.0f));
    openvdb::io::File(b.string()).write({changed});
    auto inactive = g->deepCopy();
    inactive->tree().setValueOff(openvdb::Coord(2, 2, 3), 3.0f);  // now the background: a level set's sign lost
    openvdb::io::File(c.string()).write({inactive});
    const auto r1 = bridge::compareFiles(a.string(), b.string());
    EXPECT_FALSE(r1.identical);
    ASSERT_EQ(r1.values.size(), 1u);
    EXPECT_EQ(r1.values[0].activeValues, 1u);
    const auto r2 = bridge::compareFiles(a.string(), c.string());
    ASSERT_EQ(r2.values.size(), 1u);
    EXPECT_EQ(r2.values[0].inactiveValues, 1u);
    EXPECT_TRUE(bridge::compareFiles(a.string(), a.string()).identical);
    EXPECT_GT(valueMismatchesAny(*readGrids(a)[0], *readGrids(b)[0]), 0u);
}

// `verify` compares what a decode must keep: a decoded volume that lost the
// file's metadata, or whose grids came back in another order, is reported.
// The reference is the original file as OpenVDB reads it.
TEST(VerifyNotices, LostFileMetadataAndGridOrder) {
    const fs::path file = fs::path(VDBDAG_SHARED_DATA) / "vdb" / "constant_grids.vdb";
    if (!fs::exists(file)) GTEST_SKIP() << "needs ../shared/data";
    const bridge::ImportResult imported = bridge::importVdb(file.string(), {});
    ASSERT_GE(imported.volume.grids.size(), 2u);
    ASSERT_FALSE(imported.volume.fileMetadata.empty());
    const Volume decoded = pipeline::decodeScene(format::readScene(format::writeScene(pipeline::encodeVolume(imported.volume)), "memory"));
    EXPECT_TRUE(bridge::compareWithFile(file.string(), decoded).identical);

    Volume lost = decoded;
    lost.fileMetadata.clear();
    const bridge::CompareResult noMeta = bridge::compareWithFile(file.string(), lost);
    EXPECT_FALSE(noMeta.identical);
    bool named = false;
    for (const std::string& d : noMeta.headerDifferences) named |= d.find("file metadata 'kNeighbors'") != std::string::npos;
    EXPECT_TRUE(named) << "the lost entry is not named";

    Volume swapped = decoded;
    std::swap(swapped.grids[0], swapped.grids[1]);
    EXPECT_FALSE(bridge::compareWithFile(file.string(), swapped).identical);
}
