// `info`'s header facts (src/format/GridSummary.h, vdb_bridge/VdbSummary.h)
// against independent references: the DAG's bounding box against a
// brute-force walk of every voxel; a .ssvdag's box and value range against
// OpenVDB's evalActiveVoxelBoundingBox and tools::minMax on the original
// grid; and `vdbdag info` of a .vdb and of its .ssvdag against the text
// `vdb_print -l -m` prints for the same file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <random>
#include <regex>
#include <set>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <openvdb/io/Stream.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/Count.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "src/format/GridSummary.h"
#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "tests/unit/CliRunner.h"
#include "tests/unit/TestInputs.h"
#include "vdb_bridge/VdbImport.h"

namespace fs = std::filesystem;
using namespace vdbdag;

namespace {

bridge::ImportOptions skipUnsupported() {
    bridge::ImportOptions options;
    options.skipUnsupported = true;
    return options;
}

const fs::path& folder() {
    static const fs::path d = vdbdag::testing::testFolder("grid_summary");
    return d;
}

// The scene as `info` reads it: value windows kept as they are.
format::SsvdagScene encodedAndReadBack(const Volume& volume) {
    const std::vector<uint8_t> bytes = format::writeScene(pipeline::encodeVolume(volume, {}));
    format::ReadOptions options;
    options.keepValueWindows = true;
    return format::readScene(bytes, "test", options);
}

// Brute force: every voxel of every brick and solid node.
std::optional<format::IndexBox> walkedBounds(const encoding::CompactDag& dag) {
    std::optional<format::IndexBox> box;
    auto add = [&](int64_t x, int64_t y, int64_t z) {
        if (!box) box = format::IndexBox{{x, y, z}, {x, y, z}};
        const std::array<int64_t, 3> c{x, y, z};
        for (int a = 0; a < 3; ++a) box->min[a] = std::min(box->min[a], c[a]), box->max[a] = std::max(box->max[a], c[a]);
    };
    encoding::visitInstances(
        dag,
        [&](int64_t x, int64_t y, int64_t z, uint64_t mask) {
            for (unsigned b = 0; b < 64; ++b)
                if ((mask >> b) & 1u) add(x + (b & 3), y + ((b >> 2) & 3), z + (b >> 4));
        },
        [&](int64_t x, int64_t y, int64_t z, unsigned log2Size) {
            const int64_t s = int64_t(1) << log2Size;
            add(x, y, z);
            add(x + s - 1, y + s - 1, z + s - 1);
        });
    return box;
}

} // namespace

TEST(GridSummary, DagBoundsEqualAWalkOfEveryVoxel) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 12; ++trial) {
        // Scattered voxels plus mirrored copies, so the DAG shares nodes under reflections.
        std::set<vdbdag::testing::Voxel> voxels;
        std::uniform_int_distribution<int> coord(-70 - trial * 9, 50 + trial * 5);
        for (int i = 0; i < 40 + 30 * trial; ++i) {
            const int x = coord(rng), y = coord(rng), z = coord(rng);
            voxels.insert({x, y, z});
            voxels.insert({-x - 1, y, z});
            voxels.insert({x, -y - 1, -z - 1});
        }
        Volume volume;
        GridRecord g;
        g.name = "scatter";
        g.valueType = ValueType::Mask;
        g.topology = vdbdag::testing::topologyFromVoxels(voxels);
        if (trial % 3 == 0) g.topology.tiles.push_back({64 * (trial + 1), 0, -64, 3});  // an 8^3 tile too
        volume.grids.push_back(g);
        const format::SsvdagScene scene = encodedAndReadBack(volume);
        const auto walked = walkedBounds(scene.grids[0].active.dag);
        const auto bounds = format::dagBounds(scene.grids[0].active.dag);
        ASSERT_TRUE(walked && bounds);
        EXPECT_EQ(bounds->min, walked->min) << "trial " << trial;
        EXPECT_EQ(bounds->max, walked->max) << "trial " << trial;
    }
    EXPECT_FALSE(format::dagBounds(encoding::CompactDag{}).has_value());
}

// Every shared .vdb: box, active voxel count and value range as OpenVDB computes them on the original.
TEST(GridSummary, BoxAndRangeOfAnEncodedFileAreOpenVdbsOwn) {
    std::vector<fs::path> files = vdbdag::testing::sharedVdbFiles();
    {
        openvdb::initialize();
        auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(20.0f, openvdb::Vec3f(3.0f, -2.0f, 1.0f), 0.5f, 3.0f);
        g->setName("ball");
        const fs::path p = folder() / "ball.vdb";
        openvdb::io::File f(p.string());
        f.write({g});
        f.close();
        files.push_back(p);
    }
    size_t grids = 0;
    for (const fs::path& path : files) {
        if (fs::file_size(path) > (64u << 20)) continue;
        const bridge::ImportResult imported = bridge::importVdb(path.string(), skipUnsupported());
        const format::SsvdagScene scene = encodedAndReadBack(imported.volume);
        // OpenVDB's grids in file order (names may repeat within a file).
        std::ifstream in(path, std::ios::binary);
        openvdb::io::Stream stream(in);
        const openvdb::GridPtrVecPtr originals = stream.getGrids();
        // Pair them by name and occurrence (names may repeat).
        std::map<std::string, std::vector<openvdb::GridBase::Ptr>> byName;
        for (const auto& g : *originals)
            if (!g->isType<openvdb::points::PointDataGrid>()) byName[g->getName()].push_back(g);
        std::map<std::string, size_t> seen;
        for (size_t index = 0; index < scene.grids.size(); ++index) {
            const format::EncodedGrid& grid = scene.grids[index];
            const size_t k = seen[grid.record.name]++;
            ASSERT_LT(k, byName[grid.record.name].size()) << path << " " << grid.record.name;
            const openvdb::GridBase::Ptr& base = byName[grid.record.name][k];
            ASSERT_EQ(base->getName(), grid.record.name) << path;
            const format::GridSummary s = format::summarizeGrid(grid);
            EXPECT_EQ(s.activeVoxels, base->activeVoxelCount()) << path << " " << grid.record.name;
            const openvdb::CoordBBox box = base->evalActiveVoxelBoundingBox();
            ASSERT_EQ(!box.empty(), s.indexBox.has_value()) << path;
            if (s.indexBox) {
                EXPECT_EQ(s.indexBox->min, (std::array<int64_t, 3>{box.min().x(), box.min().y(), box.min().z()})) << path << " " << grid.record.name;
                EXPECT_EQ(s.indexBox->max, (std::array<int64_t, 3>{box.max().x(), box.max().y(), box.max().z()})) << path << " " << grid.record.name;
            }
            std::string min, max;
            auto range = [&](const auto& typed) {
                const auto mm = openvdb::tools::minMax(typed.tree());
                std::ostringstream a, b;
                a << mm.min();
                b << mm.max();
                min = a.str();
                max = b.str();
            };
            if (auto f = openvdb::GridBase::grid<openvdb::FloatGrid>(base)) range(*f);
            else if (auto d = openvdb::GridBase::grid<openvdb::DoubleGrid>(base)) range(*d);
            else if (auto i = openvdb::GridBase::grid<openvdb::Int32Grid>(base)) range(*i);
            else if (auto v = openvdb::GridBase::grid<openvdb::Vec3SGrid>(base)) range(*v);
            else if (auto vi = openvdb::GridBase::grid<openvdb::Vec3IGrid>(base)) range(*vi);
            else continue;
            if (!base->activeVoxelCount()) continue;
            EXPECT_EQ(format::formatValue(grid.record.valueType, s.activeRange.min), min) << path << " " << grid.record.name;
            EXPECT_EQ(format::formatValue(grid.record.valueType, s.activeRange.max), max) << path << " " << grid.record.name;
            ++grids;
        }
    }
    EXPECT_GE(grids, 1u);
}

namespace {

// The facts `vdb_print -l -m` prints per grid, by grid name, in the order printed.
struct PrintedGrid {
    std::string bbox, min, max, voxelSize, background;
    std::map<std::string, std::string> metadata;
};
std::map<std::string, std::vector<PrintedGrid>> vdbPrint(const fs::path& file) {
    const vdbdag::testing::CommandResult r = vdbdag::testing::runShell("vdb_print -l -m " + file.string());
    std::map<std::string, std::vector<PrintedGrid>> out;
    if (r.exitCode != 0) return out;
    std::istringstream in(r.out);
    std::string line, name;
    bool inMetadata = false, inGrid = false;
    std::smatch m;
    while (std::getline(in, line)) {
        if (std::regex_match(line, m, std::regex("Name: ?(.*)"))) {
            name = m[1];
            out[name].emplace_back();
            inGrid = true;
            inMetadata = false;
            continue;
        }
        if (!inGrid) continue;
        PrintedGrid& g = out[name].back();
        if (std::regex_match(line, m, std::regex("  Bounding box of active voxels: (.*)"))) g.bbox = m[1];
        else if (std::regex_match(line, m, std::regex("  Min value: (.*)"))) g.min = m[1];
        else if (std::regex_match(line, m, std::regex("  Background value: (.*)"))) g.background = m[1];
        else if (std::regex_match(line, m, std::regex("  Max value: (.*)"))) g.max = m[1];
        else if (std::regex_match(line, m, std::regex("  voxel size: (.*)"))) g.voxelSize = m[1];
        else if (line == "Additional metadata:") inMetadata = true;
        else if (inMetadata && std::regex_match(line, m, std::regex("  ([^:]+): (.*)"))) g.metadata[m[1]] = m[2];
        else inMetadata = false;
    }
    return out;
}

// Whether `value` (a number, or three) prints as `printed` at 6 or at 3
// significant digits: vdb_print's stream is left at precision 3 after the
// first grid's percentage lines.
bool printsAs(const nlohmann::json& value, const std::string& printed) {
    for (int digits : {6, 3}) {
        std::ostringstream text;
        text << std::setprecision(digits);
        if (value.is_array()) text << "[" << value[0].get<double>() << ", " << value[1].get<double>() << ", " << value[2].get<double>() << "]";
        else text << value.get<double>();
        if (text.str() == printed) return true;
    }
    return false;
}

std::string bboxText(const nlohmann::json& b) {
    auto c = [&](const char* k) {
        return "[" + std::to_string(b[k][0].get<int64_t>()) + ", " + std::to_string(b[k][1].get<int64_t>()) + ", " + std::to_string(b[k][2].get<int64_t>()) + "]";
    };
    return c("min") + " -> " + c("max");
}

} // namespace

TEST(GridSummary, InfoOfAVdbAndOfItsSsvdagPrintWhatVdbPrintPrints) {
    if (vdbdag::testing::runShell("command -v vdb_print").exitCode != 0) GTEST_SKIP() << "needs vdb_print (openvdb-tools)";
    std::vector<fs::path> files;
    for (const fs::path& f : vdbdag::testing::sharedVdbFiles())
        if (fs::file_size(f) < (16u << 20)) files.push_back(f);
    if (files.empty()) GTEST_SKIP() << "needs ../shared/data";
    size_t checked = 0;
    for (const fs::path& vdb : files) {
        const fs::path ss = folder() / (vdb.stem().string() + ".ssvdag");
        ASSERT_EQ(vdbdag::testing::runCli("encode " + vdb.string() + " -o " + ss.string() + " -f").exitCode, 0) << vdb;
        const auto printed = vdbPrint(vdb);
        ASSERT_FALSE(printed.empty()) << vdb;
        const vdbdag::testing::CommandResult a = vdbdag::testing::runCli("info --json " + vdb.string()), b = vdbdag::testing::runCli("info --json " + ss.string());
        ASSERT_EQ(a.exitCode, 0) << a.err;
        ASSERT_EQ(b.exitCode, 0) << b.err;
        const nlohmann::json ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
        EXPECT_EQ(ja["format"], "vdb");
        EXPECT_EQ(jb["format"], "ssvdag");
        EXPECT_EQ(ja["input_bytes"].get<uint64_t>(), fs::file_size(vdb));
        {  // the file version: the u32 after the 8-byte magic of the header, read here
            std::ifstream in(vdb, std::ios::binary);
            uint8_t head[12] = {};
            in.read(reinterpret_cast<char*>(head), 12);
            EXPECT_EQ(ja["vdb_file_version"].get<uint32_t>(), uint32_t(head[8]) | uint32_t(head[9]) << 8 | uint32_t(head[10]) << 16 | uint32_t(head[11]) << 24)
                << vdb;
            const vdbdag::testing::CommandResult text = vdbdag::testing::runCli("info " + vdb.string());
            EXPECT_NE(text.out.find("OpenVDB file (format " + std::to_string(ja["vdb_file_version"].get<uint32_t>()) + ")"), std::string::npos) << text.out;
            EXPECT_NE(text.out.find(" active tiles)"), std::string::npos) << text.out;
        }
        EXPECT_EQ(jb["input_bytes"].get<uint64_t>(), fs::file_size(ss));
        EXPECT_EQ(ja["file_metadata"], jb["file_metadata"]) << vdb;
        ASSERT_EQ(ja["grids"].size(), jb["grids"].size());
        std::map<std::string, size_t> seen;
        for (size_t i = 0; i < ja["grids"].size(); ++i) {
            const nlohmann::json& ga = ja["grids"][i];
            const nlohmann::json& gb = jb["grids"][i];
            for (const char* key : {"name", "class", "value_type", "tree_type", "voxel_size", "index_to_world", "index_bbox", "world_bbox",
                                    "background", "value_range", "active_voxels"})
                EXPECT_EQ(ga[key], gb[key]) << vdb << " grid " << i << " " << key;
            const std::string name = ga["name"].get<std::string>();
            const auto it = printed.find(name);
            ASSERT_NE(it, printed.end()) << vdb << " " << name;
            const size_t k = seen[name]++;
            ASSERT_LT(k, it->second.size()) << vdb << " " << name;
            const PrintedGrid& p = it->second[k];
            if (!ga["index_bbox"].is_null()) { EXPECT_EQ(bboxText(gb["index_bbox"]), p.bbox) << vdb; }
            if (!gb["value_range"].is_null()) {
                EXPECT_TRUE(printsAs(gb["value_range"]["min"], p.min)) << vdb << " " << gb["value_range"]["min"] << " vs " << p.min;
                EXPECT_TRUE(printsAs(gb["value_range"]["max"], p.max)) << vdb << " " << gb["value_range"]["max"] << " vs " << p.max;
            }
            if (gb.contains("background") && !p.background.empty()) {
                EXPECT_TRUE(printsAs(gb["background"], p.background)) << vdb << " " << gb["background"] << " vs " << p.background;
            }
            const auto& vs = gb["voxel_size"];
            if (!p.voxelSize.empty() && vs[0] == vs[1] && vs[1] == vs[2]) {
                EXPECT_TRUE(printsAs(vs[0], p.voxelSize)) << vdb << " " << vs[0] << " vs " << p.voxelSize;
            }
            std::map<std::string, std::string> listed;
            for (const auto& [k, e] : gb["metadata"].items()) listed[k] = e["value"].get<std::string>();
            for (const auto& [k, v] : p.metadata)
                if (k.rfind("file_", 0) != 0) { EXPECT_EQ(listed[k], v) << vdb << " metadata " << k; }  // file_* are the writer's statistics
            ++checked;
        }
    }
    EXPECT_GE(checked, 5u);
}
