// Files written by an earlier vdbdag (tests/golden/, made by
// scripts/make_golden.py with the writer of format version 1) must stay
// readable by every later version: each is decoded by the current command
// and compared with its source, a .vdb tree by tree through OpenVDB's API
// (VdbTreeCompare.h) and a raw scan byte for byte; the public reader's
// Accessor must answer every active voxel of the source with OpenVDB's value.
// Never regenerate these files to make this test pass: a format change that
// cannot read them needs a reader for the old version.
#include <gtest/gtest.h>

#include <vdbdag/vdbdag.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <tuple>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"
#include "tests/unit/VdbTreeCompare.h"

using namespace vdbdag::testing;
namespace fs = std::filesystem;

namespace {

const fs::path kGolden = fs::path(VDBDAG_SOURCE_DIR) / "tests" / "golden";

std::string bytesOf(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

struct AccessorMatches {
    const vdbdag::Grid& grid;
    uint64_t& checked;
    std::string& why;
    template <typename GridT>
    void operator()(const GridT& ref) const {
        using V = typename GridT::ValueType;
        vdbdag::Accessor a = grid.accessor();
        for (auto it = ref.tree().cbeginValueOn(); it; ++it) {
            if (!it.isVoxelValue()) continue;
            const openvdb::Coord c = it.getCoord();
            ++checked;
            if (!a.isActive(c.x(), c.y(), c.z())) { why = "an active voxel reads as inactive"; return; }
            if constexpr (!std::is_same_v<V, openvdb::ValueMask>) {
                unsigned char got[sizeof(V)] = {};
                a.valueBytes(c.x(), c.y(), c.z(), got);
                const V want = *it;
                bool same;
                if constexpr (std::is_same_v<V, bool>) same = (got[0] != 0) == want;
                else same = std::memcmp(got, &want, sizeof(V)) == 0;
                if (!same) { why = "a value differs"; return; }
            }
        }
    }
};

} // namespace

TEST(Golden, VdbSourcedFilesDecodeToTheirSources) {
    openvdb::initialize();
    const fs::path dir = testFolder("golden");
    // fog_coding8 (from fog.vdb) and advected_levelset_coding8 (from frame 3
    // of `vdbdag_make_sequence OUT --frames 3 --dim 48`) as written on
    // 2026-12-05: their float values in coding 8 (predicted float bits).
    for (const auto& [name, sourceName] : {std::pair{"levelset", "levelset"}, {"fog", "fog"}, {"mixed", "mixed"}, {"fog_coding8", "fog"},
                                           {"advected_levelset_coding8", "advected_levelset"}}) {
        const fs::path golden = kGolden / (std::string(name) + ".ssvdag"), source = kGolden / (std::string(sourceName) + ".vdb");
        ASSERT_TRUE(fs::exists(golden) && fs::exists(source)) << golden;
        const fs::path back = dir / (std::string(name) + ".vdb");
        const CommandResult r = runCli("decode " + golden.string() + " -o " + back.string() + " -q");
        ASSERT_EQ(r.exitCode, 0) << r.err;
        EXPECT_EQ(sameGrids(readVdb(source), readVdb(back)), "") << name;
        const vdbdag::File file = vdbdag::File::open(golden.string());
        for (const auto& ref : readVdb(source)) {
            uint64_t checked = 0;
            std::string why;
            ASSERT_TRUE(ref->apply<openvdb::GridTypes>(AccessorMatches{file.grid(ref->getName()), checked, why}));
            EXPECT_EQ(why, "") << name << " grid '" << ref->getName() << "'";
            EXPECT_GT(checked, 100u);
        }
    }
}

TEST(Golden, ScanSourcedFileDecodesToTheSameSamples) {
    // labels (a small int16 scan, its samples in coding 1, brick residuals)
    // and scan_coding10 (a 24x24x16 crop of
    // ../shared/data/dense/headsq, its int16 CT samples in coding 10, the
    // least-squares fit, as written on 2026-12-05); scan_coding13, the same
    // crop in coding 13 (model generation 3, as written on 2026-12-06);
    // scan_coding15, in coding 15 (model generation 4, written since);
    // labels_coding17, a 32x32x16 Voronoi atlas of 24 labels in coding 17
    // (label model generation 2, written on 2026-12-06); labels_coding18, one
    // of 5 labels whose 5 uniform 8^3 blocks are tiles, in coding 18 (label
    // model generation 3, tiles as neighbours) with its attribute offsets at
    // rest (FORMAT.md 6.2), both written since 2026-12-06.
    for (const auto& [name, raw, bytes] : {std::tuple{"labels", "labels_24x20x10_int16le.raw", 24u * 20 * 10 * 2},
                                           {"labels_coding17", "labels_voronoi_32x32x16_uint8.raw", 32u * 32 * 16},
                                           {"labels_coding18", "labels_tiled_32x32x16_uint8.raw", 32u * 32 * 16},
                                           {"scan_coding10", "headsq_crop_24x24x16_int16le.raw", 24u * 24 * 16 * 2},
                                           {"scan_coding13", "headsq_crop_24x24x16_int16le.raw", 24u * 24 * 16 * 2},
                                           {"scan_coding15", "headsq_crop_24x24x16_int16le.raw", 24u * 24 * 16 * 2}}) {
        const fs::path dir = testFolder(std::string("golden_scan_") + name);
        const fs::path back = dir / raw;
        const CommandResult r = runCli("decode " + (kGolden / (std::string(name) + ".ssvdag")).string() + " -o " + back.string() + " -q");
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const std::string want = bytesOf(kGolden / raw);
        ASSERT_EQ(want.size(), bytes);
        EXPECT_TRUE(bytesOf(back) == want) << name;
    }
    const CommandResult info = runCli("info " + (kGolden / "scan_coding10.ssvdag").string());
    EXPECT_NE(info.out.find("windows: 1 fitted context-coded"), std::string::npos) << info.out;
    const CommandResult info13 = runCli("info " + (kGolden / "scan_coding13.ssvdag").string());
    EXPECT_NE(info13.out.find("windows: 1 wide fitted context-coded"), std::string::npos) << info13.out;
    const CommandResult info15 = runCli("info " + (kGolden / "scan_coding15.ssvdag").string());
    EXPECT_NE(info15.out.find("windows: 1 banded context-coded"), std::string::npos) << info15.out;
    const CommandResult info17 = runCli("info " + (kGolden / "labels_coding17.ssvdag").string());
    EXPECT_NE(info17.out.find("windows: 1 shaped labels"), std::string::npos) << info17.out;
    const CommandResult info18 = runCli("info " + (kGolden / "labels_coding18.ssvdag").string() + " --json");
    ASSERT_EQ(info18.exitCode, 0) << info18.err;
    EXPECT_NE(info18.out.find("\"solid_nodes\": 5"), std::string::npos) << info18.out;
    EXPECT_NE(runCli("info " + (kGolden / "labels_coding18.ssvdag").string()).out.find("windows: 1 tiled labels"), std::string::npos);
}
