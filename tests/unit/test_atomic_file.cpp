// Whole files in and out: format::readFileBytes (SsvdagContainer.h) names
// the file and its problem (missing, a directory, unreadable, a device, a
// FIFO); writeFileAtomically and writeViaTemporary (src/util/AtomicFile.h)
// replace the target whole by rename, and a write that fails (a file-size
// limit half way, an unwritable folder, a throwing callback) leaves the old
// file and no temporary behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "src/format/SsvdagContainer.h"
#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "tests/unit/CliRunner.h"

namespace fs = std::filesystem;
using namespace vdbdag;
using vdbdag::testing::testFolder;

namespace {

std::vector<std::string> listDir(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

std::vector<uint8_t> slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), {});
}

std::vector<uint8_t> randomBytes(size_t n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<uint8_t> v(n);
    for (auto& b : v) b = uint8_t(rng());
    return v;
}

} // namespace

TEST(ReadFileBytes, ReadsFilesAndNamesTheProblem) {
    const fs::path dir = testFolder("read");
    const auto data = randomBytes(100000, 4);
    std::ofstream(dir / "f.bin", std::ios::binary).write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
    EXPECT_EQ(format::readFileBytes((dir / "f.bin").string()), data);
    std::ofstream(dir / "empty.bin").close();
    EXPECT_TRUE(format::readFileBytes((dir / "empty.bin").string()).empty());
    try {
        format::readFileBytes((dir / "missing.ssvdag").string());
        ADD_FAILURE() << "no error for a missing file";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), (dir / "missing.ssvdag").string() + ": no such file");
    }
    EXPECT_THROW(format::readFileBytes((dir / "f.bin" / "x").string()), Error);
    try {
        format::readFileBytes(dir.string());
        ADD_FAILURE() << "no error for a directory";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
    }
    if (geteuid() != 0) {  // root reads anything
        fs::permissions(dir / "f.bin", fs::perms::none);
        EXPECT_THROW(format::readFileBytes((dir / "f.bin").string()), Error);
    }
    // Devices and FIFOs are refused before they are read (a device could be
    // read forever, a FIFO without a writer would block).
    try {
        format::readFileBytes("/dev/zero");
        ADD_FAILURE() << "no error for a device";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("is a device"), std::string::npos) << e.what();
    }
    ASSERT_EQ(::mkfifo((dir / "fifo.ssvdag").c_str(), 0600), 0);
    try {
        format::readFileBytes((dir / "fifo.ssvdag").string());
        ADD_FAILURE() << "no error for a FIFO";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("is a FIFO"), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

TEST(AtomicFile, WritesAndReplacesWithoutLeavingTemporaries) {
    const fs::path dir = testFolder("atomic");
    const fs::path target = dir / "out.bin";
    const auto a = randomBytes(10, 5), b = randomBytes(20000, 6);
    writeFileAtomically(target.string(), a);
    EXPECT_EQ(slurp(target), a);
    // An open reader of the old file keeps seeing the old bytes: the new file
    // replaced it by rename, it was not rewritten in place.
    std::ifstream old(target, std::ios::binary);
    struct stat before{};
    ASSERT_EQ(::stat(target.c_str(), &before), 0);
    writeFileAtomically(target.string(), b);
    struct stat after{};
    ASSERT_EQ(::stat(target.c_str(), &after), 0);
    EXPECT_NE(before.st_ino, after.st_ino);
    EXPECT_EQ(std::vector<uint8_t>((std::istreambuf_iterator<char>(old)), {}), a);
    EXPECT_EQ(slurp(target), b);
    EXPECT_EQ(listDir(dir), std::vector<std::string>{"out.bin"});
    // Relative paths work too (folder ".").
    const fs::path cwd = fs::current_path();
    fs::current_path(dir);
    writeFileAtomically("rel.bin", a);
    fs::current_path(cwd);
    EXPECT_EQ(listDir(dir), (std::vector<std::string>{"out.bin", "rel.bin"}));
    fs::remove_all(dir);
}

TEST(AtomicFile, FailuresLeaveNothingBehind) {
    const fs::path dir = testFolder("atomic_fail");
    const auto a = randomBytes(10, 7);
    try {
        writeFileAtomically((dir / "missing" / "x.bin").string(), a);
        ADD_FAILURE() << "no error for a missing folder";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), (dir / "missing" / "x.bin").string() + ": the folder " + (dir / "missing").string() + " does not exist");
    }
    fs::create_directories(dir / "sub");
    EXPECT_THROW(writeFileAtomically((dir / "sub").string(), a), Error);
    // A write that fails halfway (file size limit), after the temporary exists.
    writeFileAtomically((dir / "keep.bin").string(), a);
    {
        struct rlimit saved{};
        ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
        auto oldHandler = std::signal(SIGXFSZ, SIG_IGN);
        struct rlimit small = saved;
        small.rlim_cur = 4096;
        ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
        std::string message;
        try {
            writeFileAtomically((dir / "keep.bin").string(), randomBytes(100000, 8));
        } catch (const Error& e) {
            message = e.what();
        }
        ::setrlimit(RLIMIT_FSIZE, &saved);
        std::signal(SIGXFSZ, oldHandler);
        EXPECT_EQ(message.rfind((dir / "keep.bin").string() + ": write failed (", 0), 0u) << message;
    }
    EXPECT_EQ(slurp(dir / "keep.bin"), a) << "a failed write touched the existing file";
    if (geteuid() != 0) {  // root writes anywhere
        fs::permissions(dir / "sub", fs::perms::owner_read | fs::perms::owner_exec);
        EXPECT_THROW(writeFileAtomically((dir / "sub" / "x.bin").string(), a), Error);
        fs::permissions(dir / "sub", fs::perms::owner_all);
        EXPECT_TRUE(listDir(dir / "sub").empty());
    }
    EXPECT_EQ(listDir(dir), (std::vector<std::string>{"keep.bin", "sub"}));
    fs::remove_all(dir);
}

TEST(AtomicFile, WriteViaTemporary) {
    const fs::path dir = testFolder("via_tmp");
    const fs::path target = dir / "grid.vdb";
    std::string seen;
    writeViaTemporary(target.string(), [&](const std::string& tmp) {
        seen = tmp;
        std::ofstream(tmp) << "content";
    });
    EXPECT_EQ(fs::path(seen).parent_path(), dir) << "the temporary must be beside the destination";
    EXPECT_EQ(fs::path(seen).filename().string().rfind(".grid.vdb.tmp." + std::to_string(getpid()) + ".", 0), 0u) << seen;
    EXPECT_EQ(slurp(target), std::vector<uint8_t>({'c', 'o', 'n', 't', 'e', 'n', 't'}));
    // The callback throws after writing part of its file: the exception (of
    // any type) propagates and the temporary is gone; the old file survives.
    struct WriterFailure {};
    EXPECT_THROW(writeViaTemporary(target.string(),
                                   [](const std::string& tmp) {
                                       std::ofstream(tmp) << "partial";
                                       throw WriterFailure{};
                                   }),
                 WriterFailure);
    EXPECT_THROW(writeViaTemporary((dir / "never.vdb").string(),
                                   [](const std::string& tmp) {
                                       std::ofstream(tmp) << "partial";
                                       throw Error("writer failed");
                                   }),
                 Error);
    // A callback that creates nothing is an error, not a silent success.
    EXPECT_THROW(writeViaTemporary((dir / "nothing.vdb").string(), [](const std::string&) {}), Error);
    EXPECT_THROW(writeViaTemporary((dir / "no" / "x.vdb").string(), [](const std::string&) { ADD_FAILURE() << "called for a missing folder"; }),
                 Error);
    EXPECT_EQ(listDir(dir), std::vector<std::string>{"grid.vdb"});
    EXPECT_EQ(slurp(target).size(), 7u);
    fs::remove_all(dir);
}
