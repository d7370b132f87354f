// Read limits (--max-memory, --max-voxels; format/ReadLimits.h): what a
// forged file implies is weighed before anything is inflated or decoded.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "src/format/SsvdagFile.h"
#include "src/pipeline/GridCodec.h"
#include "src/util/Error.h"
#include "tests/tools/ForgedScenes.h"
#include "tests/unit/AllocationProbe.h"

using namespace vdbdag;
using format::Section;
using format::SectionKind;
using test::AllocationProbe;

// A few kilobytes may hold a genuine zstd frame of any size in a known
// section: what the table declares is weighed against --max-memory before
// anything is inflated.
TEST(ReadLimits, DeclaredSectionSizesAreWeighedBeforeAnyIsInflated) {
    const std::vector<Section> sections{{SectionKind::DagInner, 0, std::vector<uint8_t>(size_t(64) << 20, 0)}};
    const auto bytes = format::writeContainer(sections);
    ASSERT_LT(bytes.size(), size_t(64) << 10);
    format::ReadLimits limits;
    limits.maxMemory = uint64_t(16) << 20;
    {
        AllocationProbe probe;
        try {
            format::readContainer(bytes, "bomb.ssvdag", false, limits);
            ADD_FAILURE() << "a 64 MiB section passed a 16 MiB limit";
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.rfind("bomb.ssvdag: ", 0), 0u) << m;
            EXPECT_NE(m.find("--max-memory"), std::string::npos) << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        }
        EXPECT_LT(probe.largest(), size_t(1) << 20) << "inflated before the check";
    }
    limits.maxMemory = uint64_t(65) << 20;
    EXPECT_EQ(format::readContainer(bytes, "bomb.ssvdag", false, limits).front().data.size(), size_t(64) << 20);
}

// A DAG shares its subtrees, so its file can stand for far more voxels than
// it holds: a solid 64^3 block of full bricks (262,144 entries, a closed
// form) is a few hundred bytes. --max-voxels and --max-memory refuse it by
// the entries the DAG implies, before any is decoded.
TEST(ReadLimits, AnExpandingDagIsRefusedByItsEntriesBeforeDecoding) {
    GridRecord record;
    record.name = "block";
    record.gridClass = "fog volume";
    record.vdbDescriptor = {1};
    for (int z = 0; z < 64; z += 4)
        for (int y = 0; y < 64; y += 4)
            for (int x = 0; x < 64; x += 4) record.topology.bricks.push_back({x, y, z, ~uint64_t(0)});
    format::SsvdagScene scene;
    scene.grids.push_back(pipeline::encodeGrid(record));
    const auto bytes = format::writeScene(scene);
    ASSERT_LT(bytes.size(), size_t(4096));
    const uint64_t entries = 64 * 64 * 64;
    auto refusal = [&](const format::ReadOptions& options) -> std::string {
        try {
            format::readScene(bytes, "block.ssvdag", options);
        } catch (const Error& e) {
            return e.what();
        }
        return "";
    };
    format::ReadOptions options;
    options.limits.maxVoxels = entries - 1;
    std::string m = refusal(options);
    EXPECT_NE(m.find("--max-voxels"), std::string::npos) << m;
    EXPECT_NE(m.find(std::to_string(entries)), std::string::npos) << m;
    EXPECT_EQ(m.rfind("block.ssvdag: grid 0", 0), 0u) << m;
    options.limits.maxVoxels = entries;
    EXPECT_EQ(refusal(options), "");
    // Memory: a decode that builds one copy of every (1-byte, topology-only) value needs at least `entries` bytes beyond the sections.
    options.limits.valueCopies = 1;
    options.limits.maxMemory = entries - 1;
    m = refusal(options);
    EXPECT_NE(m.find("--max-memory"), std::string::npos) << m;
    options.limits.maxMemory = entries + (uint64_t(1) << 20);
    EXPECT_EQ(refusal(options), "");
}

// A DAG whose origin lies inside int32 but whose voxels reach past it
// (issue 38 #10): refused when the file is read, naming the file and the
// index, not when a decode reaches the voxel (the message had no file
// name, and `info` accepted the file).
TEST(ReadLimits, VoxelsPastTheInt32IndexRangeAreRefusedWhenRead) {
    GridRecord record;
    record.name = "far";
    record.gridClass = "fog volume";
    record.vdbDescriptor = {1};
    record.topology.bricks.push_back({0, 0, 0, ~uint64_t(0)});
    record.topology.bricks.push_back({8, 0, 0, ~uint64_t(0)});
    format::SsvdagScene scene;
    scene.grids.push_back(pipeline::encodeGrid(record));
    ASSERT_EQ(scene.grids[0].active.dag.log2Size, 4u);
    scene.grids[0].active.dag.origin[0] = 2147483640;  // a multiple of 4 inside int32; the brick at +8 lies past INT32_MAX
    const auto bytes = format::writeScene(scene);
    std::string m;
    try {
        format::readScene(bytes, "far.ssvdag");
    } catch (const Error& e) {
        m = e.what();
    }
    EXPECT_EQ(m.rfind("far.ssvdag: grid 0", 0), 0u) << m;
    EXPECT_NE(m.find("2147483651"), std::string::npos) << m;  // the last voxel index on x: 2147483640 + 11
    EXPECT_NE(m.find("outside OpenVDB's int32 index range"), std::string::npos) << m;
}

// A file of the layout before value windows keeps its values in one Values
// (palette) or PredictedValues section, which no reader can leave in the
// file: `info`, which otherwise reads values window by window, decoded all
// of them without weighing them (issue 38 #3: a 1.6 KB file took 4.2 GB
// under --max-memory 100M). A solid 128^3 float block, 8 MiB of values.
TEST(ReadLimits, ValuesOfTheLayoutBeforeWindowsAreWeighedWhenWindowsAreKept) {
    GridRecord record = vdbdag::testing::solidFloatBlock("legacy", 128);
    const uint64_t entries = uint64_t(128) * 128 * 128;
    for (uint64_t i = 0; i < entries; ++i) {
        const float v = float(i % 7) * 0.25f;
        std::memcpy(record.values.bricks.data() + i * 4, &v, 4);
    }
    format::SsvdagScene scene;
    scene.grids.push_back(pipeline::encodeGrid(record));
    vdbdag::testing::useLegacyValues(scene.grids[0]);
    const auto bytes = format::writeScene(scene);
    bool hasPalette = false;
    for (const Section& s : format::readContainer(bytes, "legacy"))
        if (s.kind == SectionKind::Values) hasPalette = true;
    ASSERT_TRUE(hasPalette) << "the forged file must keep its values in a Values section";
    ASSERT_LT(bytes.size(), size_t(1) << 20);

    format::ReadOptions options;
    options.keepValueWindows = true;  // as `info` reads
    options.limits.maxMemory = uint64_t(4) << 20;
    std::string m;
    {
        AllocationProbe probe;
        try {
            format::readScene(bytes, "legacy.ssvdag", options);
        } catch (const Error& e) {
            m = e.what();
        }
        EXPECT_LT(probe.largest(), size_t(4) << 20) << "decoded before the check";
    }
    EXPECT_EQ(m.rfind("legacy.ssvdag: grid 0", 0), 0u) << m;
    EXPECT_NE(m.find("--max-memory"), std::string::npos) << m;
    // Within the limit the values are read as they were written: the
    // count of each of the seven values (the order is the DAG's).
    options.limits.maxMemory = uint64_t(64) << 20;
    const format::SsvdagScene read = format::readScene(bytes, "legacy.ssvdag", options);
    ASSERT_EQ(read.grids[0].active.attributes.size(), entries * 4);
    std::array<uint64_t, 7> counts{};
    for (uint64_t i = 0; i < entries; ++i) {
        float v = 0;
        std::memcpy(&v, read.grids[0].active.attributes.data() + 4 * i, 4);
        const int k = int(v * 4.0f);
        ASSERT_TRUE(k >= 0 && k < 7 && float(k) * 0.25f == v) << v;
        ++counts[size_t(k)];
    }
    for (int k = 0; k < 7; ++k) EXPECT_EQ(counts[size_t(k)], entries / 7 + (uint64_t(k) < entries % 7 ? 1 : 0)) << k;
}
