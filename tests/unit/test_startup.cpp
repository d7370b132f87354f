// What a call costs before it does anything: OpenImageIO (and the two
// hundred libraries it brings) is loaded only by the commands that write a
// picture, from libvdbdag_images.so beside the program. The dynamic
// linker's own trace (LD_DEBUG=files) is the independent witness of what a
// process loaded.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include "tests/unit/BuildPaths.h"
#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;

namespace {

using vdbdag::testing::CommandResult;
using vdbdag::testing::runCli;
using vdbdag::testing::runShell;

fs::path workDir() {
    static const fs::path dir = vdbdag::testing::testFolder("startup");
    return dir;
}

fs::path encodedBall() {
    const fs::path vdb = workDir() / "ball.vdb", encoded = workDir() / "ball.ssvdag";
    if (!fs::exists(encoded)) {
        openvdb::initialize();
        auto g = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(12.0f, openvdb::Vec3f(0.0f), 1.0f, 3.0f);
        g->setName("ball");
        openvdb::io::File(vdb.string()).write({g});
        const CommandResult r = runCli("encode " + vdb.string() + " -o " + encoded.string());
        EXPECT_EQ(r.exitCode, 0) << r.err;
    }
    return encoded;
}

bool loadedOpenImageIO(const std::string& linkerTrace) { return linkerTrace.find("libOpenImageIO.so") != std::string::npos; }

} // namespace

// A PNG is written by vdbdag itself (zlib): only .exr and other formats load
// OpenImageIO's hundreds of libraries (issue 38 #9: a render under a 1 GB
// address-space cap failed mapping them).
TEST(Startup, OnlyCommandsThatWriteAnExrOrOtherPictureLoadOpenImageIO) {
    const fs::path encoded = encodedBall();
    for (const std::string& args : std::vector<std::string>{"--version", "info " + encoded.string(), "verify " + (workDir() / "ball.vdb").string() + " --encoded " + encoded.string(),
                                   "decode " + encoded.string() + " -o " + (workDir() / "back.vdb").string() + " -f"}) {
        const CommandResult r = runCli(args, "env LD_DEBUG=files ");
        EXPECT_EQ(r.exitCode, 0) << args << "\n" << r.err.substr(0, 2000);
        EXPECT_NE(r.err.find("calling init"), std::string::npos) << "no linker trace: the check would prove nothing";
        EXPECT_FALSE(loadedOpenImageIO(r.err)) << args;
    }
    const fs::path png = workDir() / "ball.png", exr = workDir() / "ball.exr";
    CommandResult r = runCli("render " + encoded.string() + " -o " + png.string() + " -f --backend cpu --width 32 --height 24", "env LD_DEBUG=files ");
    ASSERT_EQ(r.exitCode, 0) << r.err.substr(0, 2000);
    EXPECT_NE(r.err.find("calling init"), std::string::npos) << "no linker trace: the check would prove nothing";
    EXPECT_FALSE(loadedOpenImageIO(r.err));
    EXPECT_TRUE(fs::exists(png));
    r = runCli("render " + encoded.string() + " -o " + exr.string() + " -f --backend cpu --width 32 --height 24", "env LD_DEBUG=files ");
    ASSERT_EQ(r.exitCode, 0) << r.err.substr(0, 2000);
    EXPECT_TRUE(loadedOpenImageIO(r.err));
    EXPECT_TRUE(fs::exists(exr));
}

// Issue 38 #9: a PNG render under a 1 GB address-space cap (an embedded
// renderer's), then under 256 MB; OpenImageIO's own reader checks the file.
TEST(Startup, APngRenderFitsUnderASmallAddressSpaceCap) {
    const fs::path encoded = encodedBall();
    for (const char* cap : {"1048576", "262144"}) {
        const fs::path png = workDir() / (std::string("capped_") + cap + ".png");
        const CommandResult r = runShell(std::string("ulimit -v ") + cap + "; " + VDBDAG_BINARY + " render " + encoded.string() + " -o " + png.string() +
                                         " -f --backend cpu --width 64 --height 64");
        EXPECT_EQ(r.exitCode, 0) << cap << ": " << r.err;
        const CommandResult check = runShell("iinfo -v " + png.string());
        EXPECT_EQ(check.exitCode, 0) << check.out << check.err;
        EXPECT_NE(check.out.find("3 channel, uint8 png"), std::string::npos) << check.out;
    }
}

TEST(Startup, RenderWithoutTheImageModuleIsAOneLineErrorAndWritesNothing) {
    const fs::path encoded = encodedBall();
    const fs::path alone = workDir() / "alone";
    fs::create_directories(alone);
    fs::copy_file(VDBDAG_BINARY, alone / "vdbdag", fs::copy_options::overwrite_existing);
    const fs::path png = workDir() / "nothing.exr";  // a PNG needs no module
    const auto before = std::distance(fs::directory_iterator(workDir()), fs::directory_iterator());
    const CommandResult r = runShell((alone / "vdbdag").string() + " render " + encoded.string() + " -o " + png.string() + " --backend cpu --width 16 --height 16");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(png.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("libvdbdag_images.so"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(png));
    EXPECT_EQ(std::distance(fs::directory_iterator(workDir()), fs::directory_iterator()), before) << "a temporary was left behind";
}

namespace {

bool loaded(const std::string& linkerTrace, const std::string& library) { return linkerTrace.find(library) != std::string::npos; }

} // namespace

// `vdbdag` links neither VTK nor GDCM (the linker's trace is the witness);
// the calls that need them run vdbdag-full with the same command line and
// do their work: export and diff (VTK), DICOM input (GDCM).
TEST(Startup, VtkAndDicomLoadOnlyInTheCallsThatNeedThem) {
    const fs::path encoded = encodedBall();
    for (const std::string& args : {std::string("--version"), "info " + encoded.string(), "decode " + encoded.string() + " -o " + (workDir() / "b2.vdb").string() + " -f"}) {
        const CommandResult r = runCli(args, "env LD_DEBUG=files ");
        ASSERT_EQ(r.exitCode, 0) << args;
        ASSERT_NE(r.err.find("calling init"), std::string::npos) << "no linker trace: the check would prove nothing";
        EXPECT_FALSE(loaded(r.err, "libvtkCommonCore")) << args;
        EXPECT_FALSE(loaded(r.err, "libgdcmMSFF")) << args;
        EXPECT_FALSE(loaded(r.err, "vdbdag-full")) << args;
    }
    const fs::path vtu = workDir() / "ball.vtu";
    CommandResult r = runCli("export " + encoded.string() + " -o " + vtu.string() + " -f", "env LD_DEBUG=files ");
    ASSERT_EQ(r.exitCode, 0) << r.err.substr(0, 2000);
    EXPECT_TRUE(loaded(r.err, "libvtkIOXML")) << "export ran without VTK?";
    EXPECT_TRUE(fs::exists(vtu) && fs::file_size(vtu) > 0);
    // diff keeps its exit codes through the helper: 0 the same, 1 they differ, 2 an error.
    EXPECT_EQ(runCli("diff " + (workDir() / "ball.vdb").string() + " " + encoded.string()).exitCode, 0);
    EXPECT_EQ(runCli("diff " + (workDir() / "ball.vdb").string() + " " + (workDir() / "missing.vdb").string()).exitCode, 2);
    const fs::path pet = fs::path(VDBDAG_SHARED_DATA) / "medical/dicom/rsna_2/PET";
    if (fs::is_directory(pet)) {
        r = runCli("info " + pet.string() + " --json", "env LD_DEBUG=files ");
        ASSERT_EQ(r.exitCode, 0);
        EXPECT_TRUE(loaded(r.err, "libgdcmMSFF"));
        const std::string json = r.out;
        EXPECT_NE(json.find("\"format\": \"dicom\""), std::string::npos) << json.substr(0, 400);
    }
    // Without vdbdag-full beside it, such a call is a one-line error.
    const fs::path alone = workDir() / "alone_full";
    fs::create_directories(alone);
    fs::copy_file(VDBDAG_BINARY, alone / "vdbdag", fs::copy_options::overwrite_existing);
    r = runShell((alone / "vdbdag").string() + " export " + encoded.string() + " -o " + (workDir() / "none.vtu").string());
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("vdbdag-full"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(workDir() / "none.vtu"));
}
