// Sequence files (issue 43): the frames of a cache in one .ssvdag file.
// The frames come from vdbdag_make_sequence (an advected level set and its
// fog, OpenVDB's own tools), written here two grids and file metadata per
// frame; every check reads the sources with OpenVDB: each decoded frame
// holds its source's grids, metadata, active voxels and values bit for bit,
// and the reader library's frames give OpenVDB's values.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <vdbdag/vdbdag.h>

#include "tests/unit/BuildPaths.h"
#include "src/format/FrameSequence.h"
#include "src/format/SsvdagFile.h"
#include "src/util/Error.h"
#include "src/util/FramePattern.h"
#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;
using vdbdag::testing::runShell;

namespace {

const std::string kVdbdag = VDBDAG_BINARY;
constexpr int kFrames[] = {3, 4, 5, 7};  // numbered as a cache may be: from 3, frame 6 missing

std::string frameName(const fs::path& dir, const std::string& stem, int frame) {
    char name[32];
    std::snprintf(name, sizeof name, ".%04d.vdb", frame);
    return (dir / (stem + name)).string();
}

openvdb::GridPtrVecPtr readGrids(const std::string& path, openvdb::MetaMap::Ptr* meta = nullptr) {
    openvdb::io::File file(path);
    file.open();
    openvdb::GridPtrVecPtr grids = file.getGrids();
    if (meta) *meta = file.getMetadata();
    file.close();
    return grids;
}

// The folder of frames: "both.NNNN.vdb" holding the level set and the fog
// of one frame of the advected sphere, and file metadata naming it.
struct Frames {
    fs::path dir;
    Frames() {
        dir = vdbdag::testing::testFolder("sequence_file");
        const fs::path made = dir / "made";
        EXPECT_EQ(runShell(std::string(VDBDAG_SEQUENCE_TOOL) + " " + made.string() + " --frames 5 --dim 48 >/dev/null").exitCode, 0);
        openvdb::initialize();
        for (size_t i = 0; i < std::size(kFrames); ++i) {
            openvdb::GridPtrVec grids;
            for (const char* stem : {"levelset", "fog"}) grids.push_back(readGrids(frameName(made, stem, int(i) + 1))->at(0));
            openvdb::MetaMap meta;
            meta.insertMeta("shot", openvdb::StringMetadata("seq_" + std::to_string(kFrames[i])));
            meta.insertMeta("frame", openvdb::Int32Metadata(kFrames[i]));
            openvdb::io::File out(frameName(dir, "both", kFrames[i]));
            out.write(grids, meta);
            out.close();
        }
    }
    ~Frames() { if (!getenv("KEEP_TEST_DIR")) fs::remove_all(dir); }
};

const Frames& frames() {
    static const Frames f;
    return f;
}

// Every active voxel and value, the background and the class of `a` in `b`, and back.
void expectSameGrid(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b, const std::string& what) {
    EXPECT_EQ(a.getName(), b.getName()) << what;
    EXPECT_EQ(a.getGridClass(), b.getGridClass()) << what;
    EXPECT_EQ(a.activeVoxelCount(), b.activeVoxelCount()) << what;
    EXPECT_EQ(a.background(), b.background()) << what;
    auto acc = b.getConstAccessor();
    uint64_t differ = 0;
    for (auto it = a.tree().cbeginValueOn(); it; ++it) {
        float v;
        if (!acc.probeValue(it.getCoord(), v) || std::memcmp(&v, &*it, 4) != 0) ++differ;
    }
    EXPECT_EQ(differ, 0u) << what;
}

void expectSameFile(const std::string& source, const std::string& decoded) {
    openvdb::MetaMap::Ptr metaA, metaB;
    const auto a = readGrids(source, &metaA), b = readGrids(decoded, &metaB);
    ASSERT_EQ(a->size(), b->size()) << decoded;
    for (size_t g = 0; g < a->size(); ++g)
        expectSameGrid(*openvdb::gridPtrCast<openvdb::FloatGrid>(a->at(g)), *openvdb::gridPtrCast<openvdb::FloatGrid>(b->at(g)), decoded);
    EXPECT_EQ(metaA->metaValue<std::string>("shot"), metaB->metaValue<std::string>("shot")) << decoded;
    EXPECT_EQ(metaA->metaValue<int32_t>("frame"), metaB->metaValue<int32_t>("frame")) << decoded;
}

std::string bytesOf(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

} // namespace

TEST(SequenceFile, PatternEncodesEveryFrameAndDecodesEachBitExact) {
    const fs::path dir = frames().dir;
    const std::string seq = (dir / "both.ssvdag").string();
    // The default output: the pattern's name without the frame token.
    const auto encoded = runShell("cd " + dir.string() + " && " + kVdbdag + " encode 'both.####.vdb' --json");
    ASSERT_EQ(encoded.exitCode, 0) << encoded.err;
    const auto report = nlohmann::json::parse(encoded.out);
    EXPECT_EQ(report["frames"].get<size_t>(), std::size(kFrames));
    EXPECT_EQ(report["bytes"].get<uint64_t>(), fs::file_size(seq));

    // info lists the frames with their numbers and grids.
    const auto info = runShell(kVdbdag + " info " + seq + " --json");
    ASSERT_EQ(info.exitCode, 0) << info.err;
    const auto listed = nlohmann::json::parse(info.out)["frames"];
    ASSERT_EQ(listed.size(), std::size(kFrames));
    for (size_t i = 0; i < listed.size(); ++i) {
        EXPECT_EQ(listed[i]["frame"].get<int64_t>(), kFrames[i]);
        EXPECT_EQ(listed[i]["grid_count"].get<uint32_t>(), 2u);
        EXPECT_EQ(listed[i]["first_grid"].get<uint32_t>(), 2 * i);
    }

    // Every frame back, each to its own file, against its source (OpenVDB).
    const auto decoded = runShell(kVdbdag + " decode " + seq + " -o '" + (dir / "out.%04d.vdb").string() + "'");
    ASSERT_EQ(decoded.exitCode, 0) << decoded.err;
    for (int f : kFrames) expectSameFile(frameName(dir, "both", f), frameName(dir, "out", f));
    EXPECT_FALSE(fs::exists(frameName(dir, "out", 6)));

    // One frame, by number, to a named file; a selection of two.
    ASSERT_EQ(runShell(kVdbdag + " decode " + seq + " --frames 5 -o " + (dir / "five.vdb").string()).exitCode, 0);
    expectSameFile(frameName(dir, "both", 5), (dir / "five.vdb").string());
    ASSERT_EQ(runShell(kVdbdag + " decode " + seq + " --frames 4-5 -o '" + (dir / "sel.####.vdb").string() + "'").exitCode, 0);
    EXPECT_TRUE(fs::exists(frameName(dir, "sel", 4)) && fs::exists(frameName(dir, "sel", 5)));
    EXPECT_FALSE(fs::exists(frameName(dir, "sel", 3)) || fs::exists(frameName(dir, "sel", 7)));

    // verify, frame by frame, against the sources.
    EXPECT_EQ(runShell(kVdbdag + " verify '" + (dir / "both.####.vdb").string() + "' --encoded " + seq).exitCode, 0);
    EXPECT_EQ(runShell(kVdbdag + " verify " + frameName(dir, "both", 7) + " --encoded " + seq).exitCode, 0);
    // ... and a source the sequence lacks is a difference.
    fs::copy_file(frameName(dir, "both", 7), frameName(dir, "extra", 7));
    fs::copy_file(frameName(dir, "both", 5), frameName(dir, "extra", 8));
    EXPECT_EQ(runShell(kVdbdag + " verify '" + (dir / "extra.####.vdb").string() + "' --encoded " + seq + " >/dev/null").exitCode, 1);
}

TEST(SequenceFile, SameBytesFromAListAndUnderAMemoryLimitAndOneThread) {
    const fs::path dir = frames().dir;
    const std::string a = (dir / "a.ssvdag").string(), b = (dir / "b.ssvdag").string(), c = (dir / "c.ssvdag").string();
    ASSERT_EQ(runShell(kVdbdag + " encode '" + (dir / "both.$F4.vdb").string() + "' -o " + a).exitCode, 0);
    std::string list;
    for (int f : kFrames) list += " " + frameName(dir, "both", f);
    ASSERT_EQ(runShell(kVdbdag + " encode" + list + " -o " + b + " --threads 1").exitCode, 0);
    ASSERT_EQ(runShell(kVdbdag + " encode '" + (dir / "both.####.vdb").string() + "' -o " + c + " --memory-limit 64M").exitCode, 0);
    EXPECT_EQ(bytesOf(a), bytesOf(b));
    EXPECT_EQ(bytesOf(a), bytesOf(c));
    // A folder holding the frames (and nothing else): the same sequence.
    fs::create_directories(dir / "folder");
    for (int f : kFrames) fs::copy_file(frameName(dir, "both", f), frameName(dir / "folder", "both", f));
    const std::string d = (dir / "folder.ssvdag").string();
    ASSERT_EQ(runShell(kVdbdag + " encode " + (dir / "folder").string() + " -o " + d).exitCode, 0);
    EXPECT_EQ(bytesOf(a), bytesOf(d));
    // The frames' own files hold the same grids: the sequence is no larger than them together.
    uint64_t frameFiles = 0;
    for (int f : kFrames) {
        const std::string one = (dir / ("one" + std::to_string(f) + ".ssvdag")).string();
        ASSERT_EQ(runShell(kVdbdag + " encode " + frameName(dir, "both", f) + " -o " + one).exitCode, 0);
        frameFiles += fs::file_size(one);
    }
    EXPECT_LE(fs::file_size(a), frameFiles);
}

#ifdef VDBDAG_MPI_BINARY
// Under mpirun the frames are spread over the processes, each frame encoded
// by one alone: the same bytes as one process.
TEST(SequenceFile, SameBytesUnderMpirun) {
    const fs::path dir = frames().dir;
    const std::string one = (dir / "one.ssvdag").string(), three = (dir / "three.ssvdag").string();
    ASSERT_EQ(runShell(kVdbdag + " encode '" + (dir / "both.####.vdb").string() + "' -o " + one).exitCode, 0);
    const auto r = runShell(std::string(VDBDAG_MPIRUN) + " --oversubscribe --allow-run-as-root -np 3 " + VDBDAG_MPI_BINARY + " encode '" +
                            (dir / "both.####.vdb").string() + "' -o " + three + " --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["per_frame"].size(), std::size(kFrames));
    EXPECT_EQ(bytesOf(one), bytesOf(three));
}
#endif

// render: each chosen frame to its image, one camera for all; a frame's
// image is the one its own file gives from that camera.
TEST(SequenceFile, RenderDrawsEachFrameFromOneCamera) {
    const fs::path dir = frames().dir;
    const std::string seq = (dir / "render.ssvdag").string();
    ASSERT_EQ(runShell(kVdbdag + " encode '" + (dir / "both.####.vdb").string() + "' -o " + seq + " --grid surface").exitCode, 0);
    const std::string common = " --backend cpu --width 64 --height 48 --json";
    const auto r = runShell(kVdbdag + " render " + seq + " -o '" + (dir / "r.####.png").string() + "' --frame 4-5" + common);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto reports = nlohmann::json::parse(r.out);
    ASSERT_EQ(reports.size(), 2u);
    EXPECT_EQ(reports[0]["camera"], reports[1]["camera"]);
    EXPECT_FALSE(fs::exists(frameName(dir, "r", 3)));
    const auto& c = reports[1]["camera"];
    std::string camera;
    for (const char* key : {"eye", "target", "up"})
        for (const auto& v : c[key]) camera += (camera.empty() ? "" : ",") + nlohmann::json(v.get<double>()).dump();
    const std::string own = (dir / "own5.ssvdag").string();
    ASSERT_EQ(runShell(kVdbdag + " encode " + frameName(dir, "both", 5) + " -o " + own + " --grid surface").exitCode, 0);
    ASSERT_EQ(runShell(kVdbdag + " render " + own + " -o " + (dir / "own5.png").string() + " --camera " + camera + common).exitCode, 0);
    std::string r5 = frameName(dir, "r", 5);
    r5.replace(r5.size() - 4, 4, ".png");
    std::string r4 = frameName(dir, "r", 4);
    r4.replace(r4.size() - 4, 4, ".png");
    EXPECT_EQ(bytesOf(r5), bytesOf((dir / "own5.png").string()));
    EXPECT_NE(bytesOf(r4), bytesOf(r5));  // the surface moved
    // Several frames to one image: refused, nothing written.
    const auto refused = runShell(kVdbdag + " render " + seq + " -o " + (dir / "all.png").string() + common);
    EXPECT_NE(refused.exitCode, 0);
    EXPECT_NE(refused.err.find("--frame N"), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(dir / "all.png"));
}

TEST(SequenceFile, ReaderLibraryGivesEachFramesValues) {
    const fs::path dir = frames().dir;
    const std::string seq = (dir / "lib.ssvdag").string();
    ASSERT_EQ(runShell(kVdbdag + " encode '" + (dir / "both.####.vdb").string() + "' -o " + seq).exitCode, 0);
    const vdbdag::File file = vdbdag::File::open(seq);
    ASSERT_TRUE(file.isSequence());
    ASSERT_EQ(file.frames().size(), std::size(kFrames));
    for (size_t i = 0; i < std::size(kFrames); ++i) {
        EXPECT_EQ(file.frames()[i].number, kFrames[i]);
        const auto sources = readGrids(frameName(dir, "both", kFrames[i]));
        for (const auto& base : *sources) {
            const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
            vdbdag::Accessor acc = file.grid(grid->getName(), kFrames[i]).accessor();
            uint64_t differ = 0;
            for (auto it = grid->tree().cbeginValueOn(); it; ++it) {
                const openvdb::Coord c = it.getCoord();
                if (!acc.isActive(c.x(), c.y(), c.z()) || acc.value<float>(c.x(), c.y(), c.z()) != *it) ++differ;
            }
            EXPECT_EQ(differ, 0u) << grid->getName() << " frame " << kFrames[i];
        }
    }
    EXPECT_THROW(file.grid("surface", 6), vdbdag::Error);
    EXPECT_THROW(file.grid("nothing", 3), vdbdag::Error);
}

TEST(SequenceFile, RefusalsNameTheFileAndWriteNothing) {
    const fs::path dir = frames().dir;
    const std::string seq = (dir / "r.ssvdag").string();
    ASSERT_EQ(runShell(kVdbdag + " encode '" + (dir / "both.####.vdb").string() + "' -o " + seq).exitCode, 0);
    // No frame matches the pattern.
    auto r = runShell(kVdbdag + " encode '" + (dir / "none.####.vdb").string() + "' -o " + (dir / "none.ssvdag").string());
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("none.####.vdb: no file matches"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "none.ssvdag"));
    // Several frames to one file without a frame token.
    r = runShell(kVdbdag + " decode " + seq + " -o " + (dir / "all.vdb").string());
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("holds 4 frames, 3 to 7"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "all.vdb"));
    // A selection of no frame.
    r = runShell(kVdbdag + " decode " + seq + " --frames 100-200 -o '" + (dir / "x.####.vdb").string() + "'");
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("selects none"), std::string::npos) << r.err;
    // A damaged frame: one line naming it, and no sequence file.
    const std::string bad = frameName(dir, "bad", 1);
    fs::copy_file(frameName(dir, "both", 3), bad);
    fs::resize_file(bad, fs::file_size(bad) / 2);
    fs::copy_file(frameName(dir, "both", 4), frameName(dir, "bad", 2));
    r = runShell(kVdbdag + " encode '" + (dir / "bad.####.vdb").string() + "' -o " + (dir / "bad.ssvdag").string());
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("bad.0001.vdb"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "bad.ssvdag"));
    for (const auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
}

// A cache whose frames also hold a grid that does not change (a collider):
// its sections are stored once (SameAs), every frame still decodes whole,
// and one frame read alone takes them from the first frame.
openvdb::FloatGrid::Ptr staticFrames(const fs::path& dir) {
    openvdb::FloatGrid::Ptr collider = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.2f, openvdb::Vec3f(0.5f), 1.0f / 64);
    collider->setName("collider");
    for (int f : kFrames) {
        openvdb::GridPtrVec grids{readGrids(frameName(dir, "both", f))->at(0), collider};
        openvdb::io::File out(frameName(dir, "static", f));
        out.write(grids);
        out.close();
    }
    return collider;
}

TEST(SequenceFile, AnUnchangedGridIsStoredOnce) {
    const fs::path dir = frames().dir;
    const openvdb::FloatGrid::Ptr collider = staticFrames(dir);
    const std::string seq = (dir / "static.ssvdag").string();
    ASSERT_EQ(runShell(kVdbdag + " encode '" + (dir / "static.####.vdb").string() + "' -o " + seq).exitCode, 0);
    uint64_t frameFiles = 0, colliderAlone = 0;
    for (int f : kFrames) {
        const std::string one = (dir / ("static" + std::to_string(f) + ".ssvdag")).string();
        ASSERT_EQ(runShell(kVdbdag + " encode " + frameName(dir, "static", f) + " -o " + one).exitCode, 0);
        frameFiles += fs::file_size(one);
    }
    {
        openvdb::io::File out((dir / "collider.vdb").string());
        out.write({collider});
        out.close();
        ASSERT_EQ(runShell(kVdbdag + " encode " + (dir / "collider.vdb").string() + " -o " + (dir / "collider.ssvdag").string()).exitCode, 0);
        colliderAlone = fs::file_size(dir / "collider.ssvdag");
    }
    // The collider's sections once instead of four times.
    EXPECT_LT(fs::file_size(seq) + 2 * colliderAlone, frameFiles) << fs::file_size(seq) << " vs " << frameFiles << ", collider " << colliderAlone;
    const auto info = runShell(kVdbdag + " info " + seq);
    EXPECT_NE(info.out.find("SameAs"), std::string::npos);
    // Every frame back whole, and the last one alone.
    ASSERT_EQ(runShell(kVdbdag + " decode " + seq + " -o '" + (dir / "sback.####.vdb").string() + "'").exitCode, 0);
    for (int f : kFrames) {
        const auto a = readGrids(frameName(dir, "static", f)), b = readGrids(frameName(dir, "sback", f));
        ASSERT_EQ(a->size(), 2u);
        ASSERT_EQ(b->size(), 2u);
        for (size_t g = 0; g < 2; ++g)
            expectSameGrid(*openvdb::gridPtrCast<openvdb::FloatGrid>(a->at(g)), *openvdb::gridPtrCast<openvdb::FloatGrid>(b->at(g)), "frame " + std::to_string(f));
    }
    ASSERT_EQ(runShell(kVdbdag + " decode " + seq + " --frames 7 -o " + (dir / "last.vdb").string()).exitCode, 0);
    openvdb::io::File last((dir / "last.vdb").string());
    last.open();
    expectSameGrid(*collider, *openvdb::gridPtrCast<openvdb::FloatGrid>(last.readGrid("collider")), "frame 7 alone");
    last.close();
    EXPECT_EQ(runShell(kVdbdag + " verify '" + (dir / "static.####.vdb").string() + "' --encoded " + seq).exitCode, 0);
    const vdbdag::File file = vdbdag::File::open(seq);
    vdbdag::Accessor acc = file.grid("collider", 7).accessor();
    uint64_t differ = 0;
    for (auto it = collider->tree().cbeginValueOn(); it; ++it)
        if (acc.value<float>(it.getCoord().x(), it.getCoord().y(), it.getCoord().z()) != *it) ++differ;
    EXPECT_EQ(differ, 0u);
}

// SameAs payloads against forged ones.
TEST(SequenceFile, ForgedSameAsIsRefused) {
    using vdbdag::format::SameAsEntry;
    using vdbdag::format::SectionKind;
    const std::vector<SameAsEntry> good{{SectionKind::GridInfo, 0}, {SectionKind::DagInner, 1}};
    EXPECT_EQ(vdbdag::format::parseSameAs(vdbdag::format::serializeSameAs(good), 3, "s").size(), 2u);
    auto refused = [](const std::vector<SameAsEntry>& entries, uint32_t grid, const std::string& why) {
        try {
            vdbdag::format::parseSameAs(vdbdag::format::serializeSameAs(entries), grid, "x.ssvdag: SameAs");
            ADD_FAILURE() << "accepted: " << why;
        } catch (const vdbdag::Error& e) {
            EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
        }
    };
    refused(good, 1, "not an earlier grid");
    refused({{SectionKind::Frames, 0}}, 2, "not a grid's");
    refused({{SectionKind::SameAs, 0}}, 2, "not a grid's");
    refused({{SectionKind(77), 0}}, 2, "not a grid's");
    refused({{SectionKind::DagInner, 0}, {SectionKind::DagInner, 1}}, 2, "twice");
    refused({}, 2, "names 0 sections");
    // A file whose SameAs names a section no grid has: one line, no crash.
    const std::string dir = frames().dir.string();
    staticFrames(frames().dir);
    const std::string seq = dir + "/forge.ssvdag";
    ASSERT_EQ(runShell(kVdbdag + " encode '" + dir + "/static.####.vdb' -o " + seq + " --force").exitCode, 0);
    std::vector<vdbdag::format::Section> sections = vdbdag::format::readContainerFile(seq);
    bool forged = false;
    for (auto& s : sections)
        if (s.kind == SectionKind::SameAs && !forged) {
            s.data = vdbdag::format::serializeSameAs(std::vector<SameAsEntry>{{SectionKind::Normals, 0}});
            forged = true;
        }
    ASSERT_TRUE(forged);
    EXPECT_THROW(vdbdag::format::sectionsToScene(sections, "forge.ssvdag"), vdbdag::Error);
}

// The Frames section read against forged payloads (the format's checks).
TEST(SequenceFile, ForgedFramesAreRefused) {
    using vdbdag::format::FrameEntry;
    const std::vector<FrameEntry> good{{1, 2}, {5, 1}};
    EXPECT_NO_THROW(vdbdag::format::parseFrames(vdbdag::format::serializeFrames(good), 3, "f"));
    auto refused = [](const std::vector<FrameEntry>& frames, uint64_t grids, const std::string& why) {
        try {
            vdbdag::format::parseFrames(vdbdag::format::serializeFrames(frames), grids, "x.ssvdag: Frames");
            ADD_FAILURE() << "accepted: " << why;
        } catch (const vdbdag::Error& e) {
            EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
        }
    };
    refused(good, 4, "hold 3 grids but the file has 4");
    refused({{5, 1}, {1, 2}}, 3, "out of order");
    refused({{1, 0}, {2, 3}}, 3, "holds no grid");
    refused({}, 0, "no frames");
    std::vector<uint8_t> bytes = vdbdag::format::serializeFrames(good);
    bytes[0] = 200;  // 200 frames claimed in 24 bytes
    EXPECT_THROW(vdbdag::format::parseFrames(bytes, 3, "x"), vdbdag::Error);
}

TEST(FramePattern, TokensAndNumbers) {
    using namespace vdbdag;
    EXPECT_EQ(framePath("a/smoke.####.vdb", 42), "a/smoke.0042.vdb");
    EXPECT_EQ(framePath("smoke.%04d.vdb", 7), "smoke.0007.vdb");
    EXPECT_EQ(framePath("smoke.%d.vdb", 12345), "smoke.12345.vdb");
    EXPECT_EQ(framePath("smoke.$F4.vdb", -3), "smoke.-0003.vdb");
    EXPECT_EQ(framePath("smoke.$F.vdb", 9), "smoke.9.vdb");
    EXPECT_FALSE(isFramePattern("dir#1/smoke.vdb"));
    EXPECT_EQ(withoutFrameToken("out/smoke.####.vdb"), "out/smoke.vdb");
    EXPECT_EQ(frameNumberOf("cache/smoke_0012.nii.gz"), 12);
    EXPECT_EQ(frameNumberOf("ct_v2_scan.nii.gz"), std::nullopt);
    const auto listed = framesOfList({"s.10.vdb", "s.9.vdb", "s.11.vdb"});
    EXPECT_EQ(listed[0].number, 9);
    EXPECT_EQ(listed[2].path, "s.11.vdb");
    const auto unnamed = framesOfList({"b.vdb", "a.vdb"});
    EXPECT_EQ(unnamed[0].path, "b.vdb");
    EXPECT_EQ(unnamed[1].number, 2);
    const FrameSelection s = parseFrameSelection("1,5,9-12");
    EXPECT_TRUE(s.contains(10) && s.contains(5) && !s.contains(4) && !s.contains(13));
    EXPECT_THROW(parseFrameSelection("3-1"), Error);
    EXPECT_THROW(parseFrameSelection("a"), Error);
}
