// Nothing is lost, nothing is clobbered: black-box tests of the `vdbdag`
// binary checked against independent references only.
//
//  * Round trips (encode -> decode) keep the file metadata, the grid order,
//    every grid's metadata and the trees; the reference is OpenVDB itself,
//    through tests/tools/vdb_probe.cpp (an OpenVDB-only program) and direct
//    OpenVDB reads here.
//  * Writing commands (encode, decode, import, export, render, diff -o) never
//    change a file they must not touch; the reference is the bytes, type,
//    mode and link target of every file in the folder before and after.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;

namespace {

using vdbdag::testing::CommandResult;
using vdbdag::testing::runCli;
using vdbdag::testing::runShell;

// Every command runs under a time limit: a writer that opens a FIFO blocks.
const std::string kTimeout = "timeout -k 5 120 ";

std::string q(const fs::path& p) {  // shell-quoted
    std::string s = "'";
    for (char c : p.string()) s += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return s + "'";
}

CommandResult vdbdag(const std::string& args) { return runCli(args, kTimeout); }
CommandResult probe(const std::string& args) { return runShell(kTimeout + std::string(VDBDAG_VDB_PROBE) + " " + args); }

fs::path sharedData() { return fs::path(VDBDAG_SHARED_DATA); }

fs::path baseDir() {
    static const fs::path dir = [] {
        fs::path d = fs::temp_directory_path() / ("vdbdag_nothing_lost_" + std::to_string(getpid()));
        fs::remove_all(d);
        fs::create_directories(d);
        return d;
    }();
    return dir;
}

// Removes this process's work folder when the tests end (ctest runs every
// test in a process of its own).
class RemoveWorkFolder : public ::testing::Environment {
public:
    void TearDown() override {
        std::error_code ec;
        const fs::path d = fs::temp_directory_path() / ("vdbdag_nothing_lost_" + std::to_string(getpid()));
        if (fs::exists(d, ec)) fs::remove_all(d, ec);
    }
};
[[maybe_unused]] ::testing::Environment* const kRemoveWorkFolder = ::testing::AddGlobalTestEnvironment(new RemoveWorkFolder);

fs::path freshDir(const std::string& name) {
    const fs::path d = baseDir() / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string readBytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

// The stderr of a refusal: exactly one line, starting "vdbdag: ".
::testing::AssertionResult oneErrorLine(const CommandResult& r) {
    std::string e = r.err;
    if (!e.empty() && e.back() == '\n') e.pop_back();
    if (e.empty()) return ::testing::AssertionFailure() << "stderr is empty";
    if (e.find('\n') != std::string::npos) return ::testing::AssertionFailure() << "stderr has more than one line:\n" << r.err;
    if (e.rfind("vdbdag: ", 0) != 0) return ::testing::AssertionFailure() << "stderr does not start with 'vdbdag: ': " << r.err;
    return ::testing::AssertionSuccess();
}

// What a folder entry is, without following links and without opening FIFOs
// or devices.
struct Entry {
    mode_t mode = 0;
    dev_t rdev = 0;
    ino_t ino = 0;
    std::string link, bytes;
    bool operator==(const Entry&) const = default;
};

std::string describe(const Entry& e) {
    std::ostringstream os;
    if (S_ISLNK(e.mode)) os << "symlink -> " << e.link;
    else if (S_ISFIFO(e.mode)) os << "FIFO";
    else if (S_ISCHR(e.mode)) os << "char device " << major(e.rdev) << "," << minor(e.rdev);
    else if (S_ISREG(e.mode)) os << "regular file, " << e.bytes.size() << " bytes";
    else os << "other";
    os << ", mode " << std::oct << (e.mode & 07777) << ", inode " << std::dec << e.ino;
    return os.str();
}

using Listing = std::map<std::string, Entry>;

Listing listFolder(const fs::path& dir) {
    Listing out;
    for (const auto& de : fs::directory_iterator(dir)) {
        struct stat st{};
        if (::lstat(de.path().c_str(), &st) != 0) continue;
        Entry e;
        e.mode = st.st_mode;
        e.rdev = st.st_rdev;
        e.ino = st.st_ino;
        if (S_ISLNK(st.st_mode)) e.link = fs::read_symlink(de.path()).string();
        if (S_ISREG(st.st_mode)) e.bytes = readBytes(de.path());
        out[de.path().filename().string()] = e;
    }
    return out;
}

// Folder unchanged: same names, same bytes, types, modes, link targets and
// inodes (an atomic replacement changes the inode even with equal bytes).
::testing::AssertionResult sameListing(const Listing& before, const Listing& after) {
    std::ostringstream why;
    for (const auto& [name, e] : before) {
        const auto it = after.find(name);
        if (it == after.end()) why << "  " << name << " was removed (" << describe(e) << ")\n";
        else if (!(it->second == e)) why << "  " << name << " changed: before " << describe(e) << "; after " << describe(it->second) << "\n";
    }
    for (const auto& [name, e] : after)
        if (!before.count(name)) why << "  " << name << " appeared (" << describe(e) << ")\n";
    if (why.str().empty()) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "the folder changed:\n" << why.str();
}

// A small level set written by OpenVDB, with file and grid metadata.
void writeSphere(const fs::path& p) {
    openvdb::initialize();
    auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(12.0f, openvdb::Vec3f(0.0f), 0.5f, 3.0f);
    g->setName("ball");
    openvdb::MetaMap meta;
    meta.insertMeta("creator", openvdb::StringMetadata("test_nothing_lost"));
    openvdb::io::File f(p.string());
    f.write({g}, meta);
    f.close();
}

// A dense NRRD scan with a detached data file, written here (no vdbdag code).
void writeNrrd(const fs::path& dir, const std::string& header, const std::string& data) {
    const int nx = 24, ny = 20, nz = 16;
    std::string samples(size_t(nx * ny * nz), '\0');
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) samples[size_t((z * ny + y) * nx + x)] = char((x * 7 + y * 3 + z * 11) % 200 + 20);
    writeBytes(dir / data, samples);
    std::ofstream(dir / header) << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: " << nx << " " << ny << " " << nz
                                << "\nspacings: 1 1 1\nencoding: raw\ndata file: " << data << "\n";
}

// ---------------------------------------------------------------- probe checks

// The probe is the reference for everything below: it must see each kind of
// difference, or the round-trip tests could not fail.
TEST(NothingLostProbe, SeesEveryKindOfDifferenceAndNoneBetweenEqualFiles) {
    openvdb::initialize();
    const fs::path dir = freshDir("probe");
    auto makeGrid = [] {
        auto g = openvdb::FloatGrid::create(0.25f);
        g->setName("g");
        g->tree().setValueOn(openvdb::Coord(1, 2, 3), 1.5f);
        g->tree().setValueOn(openvdb::Coord(40, -7, 9), -2.0f);
        g->tree().addTile(1, openvdb::Coord(1024, 0, 0), 3.0f, true);
        g->insertMeta("note", openvdb::StringMetadata("kept"));
        return g;
    };
    auto makeOther = [] {
        auto h = openvdb::Int32Grid::create(-1);
        h->setName("h");
        h->tree().setValueOn(openvdb::Coord(0, 0, 0), 7);
        return h;
    };
    auto write = [&](const std::string& name, openvdb::GridPtrVec grids, const openvdb::MetaMap& meta) {
        openvdb::io::File f((dir / name).string());
        f.write(grids, meta);
        f.close();
        return dir / name;
    };
    openvdb::MetaMap fileMeta;
    fileMeta.insertMeta("creator", openvdb::StringMetadata("probe test"));
    fileMeta.insertMeta("frame", openvdb::Int32Metadata(12));
    const fs::path ref = write("ref.vdb", {makeGrid(), makeOther()}, fileMeta);
    const fs::path copy = write("copy.vdb", {makeGrid(), makeOther()}, fileMeta);
    CommandResult r = probe("same " + q(ref) + " " + q(copy));
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    r = probe("read " + q(ref));
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    r = probe("meta " + q(ref));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("\"probe test\""), std::string::npos) << r.out;
    EXPECT_LT(r.out.find("\"g\""), r.out.find("\"h\"")) << r.out;

    std::vector<std::pair<std::string, fs::path>> variants;
    {
        openvdb::MetaMap m = fileMeta;
        m.insertMeta("frame", openvdb::Int32Metadata(13));
        variants.push_back({"file metadata value", write("v1.vdb", {makeGrid(), makeOther()}, m)});
        openvdb::MetaMap n = fileMeta;
        n.removeMeta("creator");
        variants.push_back({"file metadata missing", write("v2.vdb", {makeGrid(), makeOther()}, n)});
    }
    variants.push_back({"grid order", write("v3.vdb", {makeOther(), makeGrid()}, fileMeta)});
    {
        auto g = makeGrid();
        g->insertMeta("note", openvdb::StringMetadata("changed"));
        variants.push_back({"grid metadata value", write("v4.vdb", {g, makeOther()}, fileMeta)});
        auto g2 = makeGrid();
        g2->removeMeta("note");
        g2->insertMeta("note", openvdb::Int32Metadata(0));
        variants.push_back({"grid metadata type", write("v5.vdb", {g2, makeOther()}, fileMeta)});
    }
    {
        auto g = makeGrid();
        g->tree().setValueOn(openvdb::Coord(1, 2, 3), std::nextafter(1.5f, 2.0f));  // one bit
        variants.push_back({"voxel value by one ulp", write("v6.vdb", {g, makeOther()}, fileMeta)});
        auto g2 = makeGrid();
        g2->tree().setValueOff(openvdb::Coord(40, -7, 9));
        variants.push_back({"voxel deactivated", write("v7.vdb", {g2, makeOther()}, fileMeta)});
        auto g3 = makeGrid();
        g3->tree().voxelizeActiveTiles();  // same active voxels, no tile
        variants.push_back({"tile voxelized", write("v8.vdb", {g3, makeOther()}, fileMeta)});
        auto g4 = makeGrid();
        g4->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
        variants.push_back({"transform", write("v9.vdb", {g4, makeOther()}, fileMeta)});
        auto g5 = makeGrid();
        g5->tree().root().setBackground(0.5f, /*updateChildNodes=*/true);
        variants.push_back({"background", write("v10.vdb", {g5, makeOther()}, fileMeta)});
        auto g6 = makeGrid();
        g6->tree().setValueOn(openvdb::Coord(1, 2, 3), -0.0f);
        auto g7 = makeGrid();
        g7->tree().setValueOn(openvdb::Coord(1, 2, 3), 0.0f);
        const fs::path negZero = write("v11a.vdb", {g6, makeOther()}, fileMeta), posZero = write("v11b.vdb", {g7, makeOther()}, fileMeta);
        r = probe("same " + q(negZero) + " " + q(posZero));
        EXPECT_EQ(r.exitCode, 1) << "-0 and +0 differ in one bit\n" << r.out;
    }
    variants.push_back({"grid missing", write("v12.vdb", {makeGrid()}, fileMeta)});
    for (const auto& [what, file] : variants) {
        r = probe("same " + q(ref) + " " + q(file));
        EXPECT_EQ(r.exitCode, 1) << what << " not seen:\n" << r.out << r.err;
        r = probe("same " + q(file) + " " + q(ref));
        EXPECT_EQ(r.exitCode, 1) << what << " not seen (B vs A):\n" << r.out << r.err;
    }
    // A truncated file: `read` fails.
    const std::string bytes = readBytes(ref);
    writeBytes(dir / "cut.vdb", bytes.substr(0, bytes.size() - 40));
    r = probe("read " + q(dir / "cut.vdb"));
    EXPECT_EQ(r.exitCode, 1) << r.out;
}

// ---------------------------------------------------------------- item 1: round trips

class NothingLostRoundTrip : public ::testing::TestWithParam<std::string> {};

size_t gridCount(const fs::path& p) {
    openvdb::initialize();
    openvdb::io::File f(p.string());
    f.open(false);
    const size_t n = f.readAllGridMetadata()->size();
    f.close();
    return n;
}

TEST_P(NothingLostRoundTrip, KeepsFileMetadataGridOrderGridMetadataAndTrees) {
    const fs::path in = sharedData() / GetParam();
    if (!fs::exists(in)) GTEST_SKIP() << in << " not present (../shared/data absent?)";
    std::string stem = fs::path(GetParam()).stem().string();
    const fs::path dir = freshDir("rt_" + stem);
    const fs::path enc = dir / (stem + ".ssvdag"), dec = dir / (stem + ".vdb");
    CommandResult r = vdbdag("encode " + q(in) + " -o " + q(enc));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = vdbdag("decode " + q(enc) + " -o " + q(dec));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = probe("same " + q(in) + " " + q(dec));
    EXPECT_EQ(r.exitCode, 0) << "decode of encode of " << in << " is not what OpenVDB reads from it:\n" << r.out << r.err;
    if (!r.out.empty() && r.out.find("note:") != std::string::npos) std::cout << "[ probe notes ] " << r.out;
    if (gridCount(in) > 1) {
        r = vdbdag("diff " + q(in) + " " + q(enc));
        EXPECT_EQ(r.exitCode, 0) << "vdbdag diff " << in << " " << enc << ":\n" << r.out << r.err;
        r = vdbdag("diff " + q(in) + " " + q(dec));
        EXPECT_EQ(r.exitCode, 0) << "vdbdag diff " << in << " " << dec << ":\n" << r.out << r.err;
    }
}

INSTANTIATE_TEST_SUITE_P(NothingLost, NothingLostRoundTrip,
                         ::testing::Values("vdb/constant_grids.vdb", "vdb/dense_posdensity.vdb", "vdb/double_smoke.vdb", "vdb/fog_sphere_tiny.vdb",
                                           "vdb/fog_torus.vdb", "vdb/ls_cube.vdb", "vdb/ls_sphere.vdb", "vdb/random_colors_vec3i.vdb",
                                           "vdb/smoke1.vdb", "vdb/three_density_grids.vdb", "vdb/unnamed_levelset.vdb", "vdb/unnamed_ls_bg5.vdb",
                                           "vdb/velocity_tiles.vdb", "levelsets/bunny_d512_fog.vdb"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                             std::string s = fs::path(info.param).stem().string();
                             std::replace_if(s.begin(), s.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
                             return s;
                         });

// A file made here with OpenVDB: file metadata of many types, grids in a
// non-alphabetical order (two share a name), grid metadata of many types.
fs::path writeMetadataRichFile(const fs::path& p) {
    openvdb::initialize();
    openvdb::MetaMap file;
    file.insertMeta("creator", openvdb::StringMetadata("nothing-lost test 1.0"));
    file.insertMeta("frame", openvdb::Int32Metadata(1042));
    file.insertMeta("ticks", openvdb::Int64Metadata(int64_t(1) << 40));
    file.insertMeta("fps", openvdb::FloatMetadata(23.976f));
    file.insertMeta("exposure", openvdb::DoubleMetadata(0.1));
    file.insertMeta("final", openvdb::BoolMetadata(true));
    file.insertMeta("origin", openvdb::Vec3IMetadata(openvdb::Vec3i(-3, 4, 5)));
    file.insertMeta("pivot", openvdb::Vec3DMetadata(openvdb::Vec3d(0.5, -1.25, 1e-9)));
    file.insertMeta("camera", openvdb::Mat4DMetadata(openvdb::Mat4d::identity() * 2.0));
    file.insertMeta("unicode note", openvdb::StringMetadata("caf\xc3\xa9, \"quoted\"\nsecond line"));

    auto zeta = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(6.0f, openvdb::Vec3f(1.0f, 2.0f, 3.0f), 0.5f, 3.0f);
    zeta->setName("zeta");
    zeta->insertMeta("author", openvdb::StringMetadata("someone"));
    zeta->insertMeta("iteration", openvdb::Int32Metadata(-7));
    zeta->insertMeta("scale", openvdb::DoubleMetadata(1.0 / 3.0));
    zeta->insertMeta("tint", openvdb::Vec3SMetadata(openvdb::Vec3s(0.1f, 0.2f, 0.3f)));
    auto alpha = openvdb::Int32Grid::create(-1);
    alpha->setName("alpha");
    alpha->setGridClass(openvdb::GRID_UNKNOWN);
    alpha->tree().setValueOn(openvdb::Coord(0, 0, 0), 5);
    alpha->tree().setValueOn(openvdb::Coord(9, -3, 2), 6);
    alpha->tree().addTile(2, openvdb::Coord(4096, 0, 0), 8, true);
    alpha->insertMeta("label", openvdb::StringMetadata("ids"));
    auto vel = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    vel->setName("alpha");  // a second grid of the same name
    vel->setGridClass(openvdb::GRID_STAGGERED);
    vel->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    vel->setTransform(openvdb::math::Transform::createLinearTransform(0.2));
    vel->tree().setValueOn(openvdb::Coord(3, 3, 3), openvdb::Vec3s(1.0f, -2.0f, 0.5f));
    vel->insertMeta("units", openvdb::StringMetadata("m/s"));
    auto fog = openvdb::FloatGrid::create(0.0f);
    fog->setName("mid");
    fog->setGridClass(openvdb::GRID_FOG_VOLUME);
    fog->tree().setValueOn(openvdb::Coord(-5, 0, 5), 0.75f);
    fog->insertMeta("empty string", openvdb::StringMetadata(""));
    openvdb::io::File f(p.string());
    f.write({zeta, alpha, vel, fog}, file);
    f.close();
    return p;
}

TEST(NothingLostMetadata, FileAndGridMetadataAndOrderSurviveEncodeDecode) {
    const fs::path dir = freshDir("meta");
    const fs::path in = writeMetadataRichFile(dir / "rich.vdb"), enc = dir / "rich.ssvdag", dec = dir / "rich_back.vdb";
    CommandResult r = vdbdag("encode " + q(in) + " -o " + q(enc));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = vdbdag("decode " + q(enc) + " -o " + q(dec));
    ASSERT_EQ(r.exitCode, 0) << r.err;

    // Directly with OpenVDB: every file-level item, by type and value.
    openvdb::io::File a(in.string()), b(dec.string());
    a.open(false);
    b.open(false);
    const auto ma = a.getMetadata(), mb = b.getMetadata();
    for (auto it = ma->beginMeta(); it != ma->endMeta(); ++it) {
        const auto other = (*mb)[it->first];
        if (!other) {
            ADD_FAILURE() << "file metadata '" << it->first << "' (" << it->second->str() << ") was lost";
            continue;
        }
        EXPECT_EQ(other->typeName(), it->second->typeName()) << it->first;
        EXPECT_TRUE(*other == *it->second) << it->first << ": " << it->second->str() << " became " << other->str();
    }
    EXPECT_EQ(mb->metaCount(), ma->metaCount()) << "file metadata items added";
    // (io::File lists grids sorted by name, ties in file order: the file
    // order itself is checked through the probe below.)
    const auto ga = a.readAllGridMetadata(), gb = b.readAllGridMetadata();
    ASSERT_EQ(gb->size(), ga->size());
    for (size_t i = 0; i < ga->size(); ++i) {
        EXPECT_EQ((*gb)[i]->getName(), (*ga)[i]->getName()) << "grid " << i;
        EXPECT_EQ((*gb)[i]->type(), (*ga)[i]->type()) << "grid " << i;
        for (auto it = (*ga)[i]->beginMeta(); it != (*ga)[i]->endMeta(); ++it) {
            if (it->first.rfind("file_", 0) == 0) continue;  // statistics: compared by the probe
            const auto other = (*(*gb)[i])[it->first];
            if (!other) {
                ADD_FAILURE() << "grid " << i << " '" << (*ga)[i]->getName() << "': metadata '" << it->first << "' (" << it->second->str() << ") was lost";
                continue;
            }
            EXPECT_TRUE(*other == *it->second) << "grid " << i << " metadata '" << it->first << "': " << it->second->str() << " became " << other->str();
        }
    }
    a.close();
    b.close();

    // File order, as the probe reads it: first as written here, then kept.
    auto order = [](const fs::path& p) {
        const CommandResult m = probe("meta " + q(p));
        EXPECT_EQ(m.exitCode, 0) << m.err;
        std::vector<std::string> names;
        const nlohmann::json j = nlohmann::json::parse(m.out);
        for (const auto& g : j.at("grids")) names.push_back(g["name"].get<std::string>() + ":" + g["type"].get<std::string>());
        return names;
    };
    const std::vector<std::string> written = {"zeta:Tree_float_5_4_3", "alpha:Tree_int32_5_4_3", "alpha:Tree_vec3s_5_4_3", "mid:Tree_float_5_4_3"};
    EXPECT_EQ(order(in), written) << "the probe does not see the file order";
    EXPECT_EQ(order(dec), written) << "the grid order changed";

    // The probe: the same plus the file_* rule and the trees.
    r = probe("same " + q(in) + " " + q(dec));
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    r = vdbdag("diff " + q(in) + " " + q(enc));
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
    r = vdbdag("diff " + q(in) + " " + q(dec));
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
}

// The positive case of `verify`: a faithful file verifies. (That verify fails
// when a decode loses metadata cannot be forced from outside the binary.)
TEST(NothingLostMetadata, VerifyAcceptsAFileWithFileAndGridMetadata) {
    const fs::path dir = freshDir("verify");
    const fs::path in = writeMetadataRichFile(dir / "rich.vdb");
    const CommandResult r = vdbdag("verify " + q(in));
    EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
}

// ---------------------------------------------------------------- item 2: outputs

// The inputs each output case needs, made once per case folder.
struct Inputs {
    fs::path dir, vdb, ssvdag, nhdr;
};

Inputs makeInputs(const std::string& name) {
    Inputs in;
    in.dir = freshDir(name);
    in.vdb = in.dir / "s.vdb";
    in.ssvdag = in.dir / "a.ssvdag";
    in.nhdr = in.dir / "v.nhdr";
    static const fs::path proto = [] {
        const fs::path d = freshDir("proto");
        writeSphere(d / "s.vdb");
        writeNrrd(d, "v.nhdr", "v_samples.raw");
        const CommandResult r = vdbdag("encode " + q(d / "s.vdb") + " -o " + q(d / "a.ssvdag"));
        if (r.exitCode != 0) ADD_FAILURE() << "encoding the test input failed: " << r.err;
        return d;
    }();
    for (const auto& e : fs::directory_iterator(proto)) fs::copy_file(e.path(), in.dir / e.path().filename());
    return in;
}

struct Writer {
    std::string name, ext;  // command and the extension of its output
    std::string args(const Inputs& in, const fs::path& out) const {
        if (name == "encode") return "encode " + q(in.vdb) + " -o " + q(out);
        if (name == "decode") return "decode " + q(in.ssvdag) + " -o " + q(out);
        if (name == "import") return "import " + q(in.nhdr) + " -o " + q(out);
        if (name == "export") return "export " + q(in.vdb) + " -o " + q(out);
        if (name == "render") return "render " + q(in.ssvdag) + " -o " + q(out) + " --backend cpu --width 48 --height 32";
        return "diff " + q(in.vdb) + " " + q(in.ssvdag) + " -o " + q(out);
    }
};
// GoogleTest prints a parameter without one as its raw bytes, which for a
// std::string include unset ones (valgrind reports them).
void PrintTo(const Writer& w, std::ostream* os) { *os << w.name; }

const std::vector<Writer>& writers() {
    static const std::vector<Writer> w = {{"encode", ".ssvdag"}, {"decode", ".vdb"}, {"import", ".vdb"},
                                          {"export", ".vtu"},    {"render", ".png"}, {"diff", ".vtu"}};
    return w;
}

const std::string kOldBytes = "previous output: must survive\n";

// Runs a command that must be refused and checks that nothing in the folder changed.
void expectRefused(const fs::path& dir, const std::string& args, const std::string& why) {
    SCOPED_TRACE(why + ": vdbdag " + args);
    const Listing before = listFolder(dir);
    const CommandResult r = vdbdag(args);
    EXPECT_NE(r.exitCode, 0) << "accepted; stdout: " << r.out;
    EXPECT_NE(r.exitCode, 124) << "timed out";
    EXPECT_TRUE(oneErrorLine(r));
    EXPECT_TRUE(sameListing(before, listFolder(dir)));
}

class NothingLostOutputs : public ::testing::TestWithParam<Writer> {};

TEST_P(NothingLostOutputs, ExistingRegularOutputNeedsForce) {
    const Writer& w = GetParam();
    const Inputs in = makeInputs("exist_" + w.name);
    const fs::path out = in.dir / ("out" + w.ext);
    writeBytes(out, kOldBytes);
    expectRefused(in.dir, w.args(in, out), "existing output, no --force");
}

TEST_P(NothingLostOutputs, ReadOnlyExistingOutputNeedsForce) {
    const Writer& w = GetParam();
    const Inputs in = makeInputs("readonly_" + w.name);
    const fs::path out = in.dir / ("out" + w.ext);
    writeBytes(out, kOldBytes);
    ASSERT_EQ(::chmod(out.c_str(), 0444), 0);
    expectRefused(in.dir, w.args(in, out), "read-only existing output, no --force");
}

TEST_P(NothingLostOutputs, FifoIsNeverAnOutput) {
    const Writer& w = GetParam();
    const Inputs in = makeInputs("fifo_" + w.name);
    const fs::path out = in.dir / ("out" + w.ext);
    ASSERT_EQ(::mkfifo(out.c_str(), 0644), 0);
    expectRefused(in.dir, w.args(in, out), "FIFO output");
    expectRefused(in.dir, w.args(in, out) + " --force", "FIFO output with --force");
}

TEST_P(NothingLostOutputs, CharacterDeviceIsNeverAnOutput) {
    if (::geteuid() != 0) GTEST_SKIP() << "mknod needs root";
    const Writer& w = GetParam();
    const Inputs in = makeInputs("chardev_" + w.name);
    const fs::path out = in.dir / ("out" + w.ext);
    if (::mknod(out.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0) GTEST_SKIP() << "mknod failed: " << std::strerror(errno);
    expectRefused(in.dir, w.args(in, out), "character device output");
    expectRefused(in.dir, w.args(in, out) + " --force", "character device output with --force");
}

TEST_P(NothingLostOutputs, SymlinkIsNeverAnOutput) {
    const Writer& w = GetParam();
    const Inputs in = makeInputs("symlink_" + w.name);
    const fs::path target = in.dir / ("target" + w.ext), link = in.dir / ("link" + w.ext);
    writeBytes(target, kOldBytes);
    fs::create_symlink(target.filename(), link);
    expectRefused(in.dir, w.args(in, link), "symlink output");
    expectRefused(in.dir, w.args(in, link) + " --force", "symlink output with --force");
}

::testing::AssertionResult validOutput(const Writer& w, const fs::path& out) {
    const std::string bytes = readBytes(out);
    if (bytes == kOldBytes) return ::testing::AssertionFailure() << out << " still holds the previous output";
    if (w.ext == ".vdb") {
        const CommandResult r = probe("read " + q(out));
        if (r.exitCode != 0) return ::testing::AssertionFailure() << "OpenVDB cannot read " << out << ": " << r.out << r.err;
    } else if (w.ext == ".ssvdag") {
        const CommandResult r = vdbdag("info " + q(out));
        if (r.exitCode != 0) return ::testing::AssertionFailure() << "vdbdag info " << out << ": " << r.err;
    } else if (w.ext == ".vtu") {
        if (bytes.find("<VTKFile") == std::string::npos || bytes.find("</VTKFile>") == std::string::npos)
            return ::testing::AssertionFailure() << out << " is not VTK XML";
    } else if (w.ext == ".png") {
        if (bytes.size() < 8 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return ::testing::AssertionFailure() << out << " is not a PNG";
    }
    return ::testing::AssertionSuccess();
}

TEST_P(NothingLostOutputs, ForceReplacesAnExistingRegularOutput) {
    const Writer& w = GetParam();
    for (const std::string flag : {"--force", "-f"}) {
        SCOPED_TRACE(flag);
        const Inputs in = makeInputs("force_" + w.name + flag);
        const fs::path out = in.dir / ("out" + w.ext);
        writeBytes(out, kOldBytes);
        const Listing before = listFolder(in.dir);
        const CommandResult r = vdbdag(w.args(in, out) + " " + flag);
        ASSERT_EQ(r.exitCode, 0) << "vdbdag " << w.args(in, out) << " " << flag << ": " << r.err;
        struct stat st{};
        ASSERT_EQ(::lstat(out.c_str(), &st), 0);
        EXPECT_TRUE(S_ISREG(st.st_mode)) << out << " is no longer a regular file";
        EXPECT_TRUE(validOutput(w, out));
        // Only the output changed: the inputs are intact and no temporary remains.
        Listing after = listFolder(in.dir), expected = before;
        expected.erase(out.filename().string());
        after.erase(out.filename().string());
        EXPECT_TRUE(sameListing(expected, after));
    }
}

// Without --force and with no existing output the command works (so the
// refusals above are about the output, not about the command line).
TEST_P(NothingLostOutputs, NewOutputIsWrittenWithoutForce) {
    const Writer& w = GetParam();
    const Inputs in = makeInputs("new_" + w.name);
    const fs::path out = in.dir / ("out" + w.ext);
    const CommandResult r = vdbdag(w.args(in, out));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(validOutput(w, out));
}

INSTANTIATE_TEST_SUITE_P(NothingLost, NothingLostOutputs, ::testing::ValuesIn(writers()),
                         [](const ::testing::TestParamInfo<Writer>& info) { return info.param.name; });

// Output == input: refused even with --force, however the path is spelled.
TEST(NothingLostSameFile, OutputThatIsTheInputIsRefusedEvenWithForce) {
    const Inputs in = makeInputs("samefile");
    fs::create_directories(in.dir / "sub");
    fs::create_symlink("s.vdb", in.dir / "alias.vdb");
    fs::create_symlink("a.ssvdag", in.dir / "alias.ssvdag");
    fs::create_symlink("v.nhdr", in.dir / "alias.nhdr");
    fs::create_symlink("s.vdb", in.dir / "to_input.ssvdag");  // an output name that is the input
    const std::string d = in.dir.string();
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"encode " + q(in.vdb) + " -o " + q(in.vdb), "encode s.vdb -o s.vdb"},
        {"decode " + q(in.ssvdag) + " -o " + q(in.ssvdag), "decode a.ssvdag -o a.ssvdag"},
        {"decode " + q(d + "/sub/../a.ssvdag") + " -o " + q(in.ssvdag), "decode sub/../a.ssvdag -o a.ssvdag"},
        {"decode " + q(in.dir / "alias.ssvdag") + " -o " + q(in.ssvdag), "decode via a symlinked input"},
        {"import " + q(in.nhdr) + " -o " + q(in.nhdr), "import v.nhdr -o v.nhdr"},
        {"import " + q(in.dir / "alias.nhdr") + " -o " + q(d + "/./sub/../v.nhdr"), "import alias.nhdr -o ./sub/../v.nhdr"},
        {"import " + q(in.nhdr) + " -o " + q(in.dir / "v_samples.raw"), "import v.nhdr -o its data file"},
        {"encode " + q(in.nhdr) + " -o " + q(in.dir / "v_samples.raw"), "encode v.nhdr -o its data file"},
        {"encode " + q(in.nhdr) + " -o " + q(d + "/sub/../v_samples.raw"), "encode v.nhdr -o sub/../its data file"},
        {"encode " + q(in.dir / "alias.vdb") + " -o " + q(d + "/./sub/../s.vdb"), "encode alias.vdb -o ./sub/../s.vdb"},
        {"encode " + q(in.vdb) + " -o " + q(in.dir / "to_input.ssvdag"), "encode s.vdb -o a link to s.vdb"},
    };
    for (const auto& [args, why] : cases) {
        expectRefused(in.dir, args, why);
        expectRefused(in.dir, args + " --force", why + " --force");
    }
}

// The same with a real scan from ../shared/data: its .nhdr names its data
// file, and `encode scan.nhdr -o scan.raw` must not destroy the scan.
TEST(NothingLostSameFile, EncodeOfAnNhdrOntoItsOwnDataFileIsRefused) {
    const fs::path src = sharedData() / "dense" / "cthead_256x256x99_uint8.nhdr";
    if (!fs::exists(src)) GTEST_SKIP() << src << " not present";
    std::string dataName;
    {
        std::ifstream h(src);
        for (std::string line; std::getline(h, line);)
            if (line.rfind("data file:", 0) == 0 || line.rfind("datafile:", 0) == 0) {
                dataName = line.substr(line.find(':') + 1);
                dataName.erase(0, dataName.find_first_not_of(" \t"));
                while (!dataName.empty() && std::isspace(static_cast<unsigned char>(dataName.back()))) dataName.pop_back();
            }
    }
    ASSERT_FALSE(dataName.empty()) << src << " names no data file";
    ASSERT_EQ(dataName.find('/'), std::string::npos) << "expected a relative data file name, got " << dataName;
    const fs::path dir = freshDir("scan");
    fs::copy_file(src, dir / src.filename());
    fs::copy_file(src.parent_path() / dataName, dir / dataName);
    fs::permissions(dir / src.filename(), fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::add);
    fs::permissions(dir / dataName, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::add);
    const std::string args = "encode " + q(dir / src.filename()) + " -o " + q(dir / dataName);
    expectRefused(dir, args, "encode scan.nhdr -o scan.raw");
    expectRefused(dir, args + " --force", "encode scan.nhdr -o scan.raw --force");
}

// Wrong output extensions are refused and create nothing.
TEST(NothingLostExtensions, WrongOutputExtensionsAreRefused) {
    const Inputs in = makeInputs("ext");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"encode " + q(in.vdb) + " -o " + q(in.dir / "x.vdb"), "encode X.vdb -o x.vdb"},
        {"decode " + q(in.ssvdag) + " -o " + q(in.dir / "x.vdbx"), "decode a.ssvdag -o x.vdbx"},
        {"decode " + q(in.ssvdag) + " -o " + q(in.dir / "x.ssvdag"), "decode a.ssvdag -o x.ssvdag"},
    };
    for (const auto& [args, why] : cases) expectRefused(in.dir, args, why);
}

} // namespace
