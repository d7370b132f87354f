// The library side of "nothing is ever lost": OutputPath's rules, the
// registry of temporaries that interrupts clean up, the removal of what a
// killed process left, and the checked stream OpenVDB writes into. The
// references are the file system itself (stat, directory listings) and
// bytes written by the test.
#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "tests/unit/BuildPaths.h"
#include "src/util/AtomicFile.h"
#include "src/util/Error.h"
#include "src/util/OutputPath.h"
#include "src/util/TemporaryFiles.h"

namespace fs = std::filesystem;

namespace {

struct TempFolder {
    fs::path path;
    TempFolder() {
        path = fs::temp_directory_path() / ("vdbdag_output_safety_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
        fs::remove_all(path);  // a finished process with the same PID may have left it
        fs::create_directories(path);
    }
    ~TempFolder() {
        std::error_code ec;
        fs::permissions(path, fs::perms::owner_all, fs::perm_options::add, ec);
        fs::remove_all(path, ec);
    }
    std::string operator/(const std::string& name) const { return (path / name).string(); }
    static inline int counter = 0;
};

void writeText(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string refusal(const std::string& output, const std::vector<std::string>& inputs, bool force, std::vector<std::string> ext = {".ssvdag"}) {
    try {
        vdbdag::checkOutputPath(output, inputs, {std::move(ext), "encode", force});
    } catch (const vdbdag::Error& e) {
        return e.what();
    }
    return "";
}

size_t entries(const fs::path& folder) {
    return size_t(std::distance(fs::directory_iterator(folder), fs::directory_iterator()));
}

} // namespace

TEST(OutputPath, NewFileWithTheRightExtensionIsAccepted) {
    TempFolder t;
    EXPECT_EQ(refusal(t / "a.ssvdag", {t / "in.vdb"}, false), "");
    EXPECT_EQ(refusal(t / "A.SSVDAG", {}, false), "");  // case-insensitive
}

TEST(OutputPath, WrongOrMissingExtensionIsRefused) {
    TempFolder t;
    EXPECT_NE(refusal(t / "a.vdb", {}, true).find("writes .ssvdag files"), std::string::npos);
    EXPECT_NE(refusal(t / "a", {}, true).find("has none"), std::string::npos);
    EXPECT_NE(refusal(t / "a.nvdb", {}, true, {".vdb"}).find("'.nvdb'"), std::string::npos);
}

TEST(OutputPath, TheInputIsRefusedThroughAnySpelling) {
    TempFolder t;
    writeText(t / "s.ssvdag", "x");
    fs::create_directory(t.path / "sub");
    EXPECT_NE(refusal(t / "s.ssvdag", {t / "s.ssvdag"}, true).find("is the input"), std::string::npos);
    const std::string spelled = (t.path / "sub" / ".." / "s.ssvdag").string();
    EXPECT_NE(refusal(spelled, {t / "s.ssvdag"}, true).find("same file as the input"), std::string::npos);
    fs::create_hard_link(t / "s.ssvdag", t / "hard.ssvdag");
    EXPECT_NE(refusal(t / "hard.ssvdag", {t / "s.ssvdag"}, true).find("same file as the input"), std::string::npos);
    fs::create_symlink(t / "s.ssvdag", t / "link.ssvdag");
    EXPECT_NE(refusal(t / "link.ssvdag", {t / "s.ssvdag"}, true).find("same file as the input"), std::string::npos);
    // The input's extension is the output's too: still the input, not a format question.
    EXPECT_NE(refusal(t / "s.ssvdag", {t / "s.ssvdag"}, true, {".vdb"}).find("is the input"), std::string::npos);
}

TEST(OutputPath, ExistingFilesNeedForceAndNeverLinksDevicesOrFifos) {
    TempFolder t;
    writeText(t / "old.ssvdag", "old");
    EXPECT_NE(refusal(t / "old.ssvdag", {}, false).find("already exists"), std::string::npos);
    EXPECT_EQ(refusal(t / "old.ssvdag", {}, true), "");
    writeText(t / "ro.ssvdag", "ro");
    fs::permissions(t / "ro.ssvdag", fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
    EXPECT_NE(refusal(t / "ro.ssvdag", {}, true).find("read-only"), std::string::npos);
    fs::create_symlink(t / "old.ssvdag", t / "link.ssvdag");
    EXPECT_NE(refusal(t / "link.ssvdag", {}, true).find("symbolic link"), std::string::npos);
    ASSERT_EQ(::mkfifo((t / "f.ssvdag").c_str(), 0600), 0);
    EXPECT_NE(refusal(t / "f.ssvdag", {}, true).find("FIFO"), std::string::npos);
    fs::create_directory(t.path / "d.ssvdag");
    EXPECT_NE(refusal(t / "d.ssvdag", {}, true).find("directory"), std::string::npos);
    EXPECT_NE(refusal("/dev/null", {}, true, {}).find("device"), std::string::npos);
    EXPECT_EQ(readText(t / "old.ssvdag"), "old");
}

TEST(AtomicFile, RefusesToReplaceWhatIsNotARegularFile) {
    TempFolder t;
    writeText(t / "target", "keep");
    fs::create_symlink(t / "target", t / "link");
    const std::vector<uint8_t> bytes{1, 2, 3};
    EXPECT_THROW(vdbdag::writeFileAtomically(t / "link", bytes), vdbdag::Error);
    EXPECT_TRUE(fs::is_symlink(t / "link"));
    EXPECT_EQ(readText(t / "target"), "keep");
    ASSERT_EQ(::mkfifo((t / "fifo").c_str(), 0600), 0);
    EXPECT_THROW(vdbdag::writeFileAtomically(t / "fifo", bytes), vdbdag::Error);
    EXPECT_TRUE(fs::is_fifo(t / "fifo"));
    EXPECT_EQ(entries(t.path), 3u);  // no temporary left
}

TEST(AtomicFile, StreamWriterSeeksLikeAFileAndReplacesAtomically) {
    TempFolder t;
    writeText(t / "out.bin", "previous");
    vdbdag::writeStreamAtomically(t / "out.bin", [](std::ostream& out) {
        out << "0123456789";
        const auto at = out.tellp();
        EXPECT_EQ(int64_t(at), 10);
        out.seekp(2);
        out << "ab";
        out.seekp(0, std::ios_base::end);
        out << std::string(3 << 20, 'z');  // past the 1 MiB buffer
    });
    const std::string got = readText(t / "out.bin");
    ASSERT_EQ(got.size(), 10u + (3u << 20));
    EXPECT_EQ(got.substr(0, 10), "01ab456789");
    EXPECT_EQ(entries(t.path), 1u);
}

TEST(AtomicFile, AWriterThatThrowsLeavesThePreviousFileAndNoTemporary) {
    TempFolder t;
    writeText(t / "out.bin", "previous");
    EXPECT_THROW(vdbdag::writeStreamAtomically(t / "out.bin", [](std::ostream& out) {
        out << "partial";
        throw vdbdag::Error("writer failed");
    }), vdbdag::Error);
    EXPECT_EQ(readText(t / "out.bin"), "previous");
    EXPECT_EQ(entries(t.path), 1u);
}

// Issue 38: two commands creating the same new output (no --force) both
// exited 0 and the later silently replaced the earlier. A file that appears
// after the check is never replaced; with --force it is.
TEST(AtomicFile, ANewOutputNeverReplacesAFileThatAppearedMeanwhile) {
    TempFolder t;
    const std::string out = t / "race.ssvdag";
    ASSERT_EQ(refusal(out, {}, false), "");  // absent: checked as a new output
    std::string message;
    try {
        vdbdag::writeStreamAtomically(out, [&](std::ostream& s) {
            s << "ours";
            writeText(out, "theirs");  // the other command finishes first
        });
    } catch (const vdbdag::Error& e) {
        message = e.what();
    }
    EXPECT_NE(message.find("appeared while"), std::string::npos) << message;
    EXPECT_NE(message.find(out), std::string::npos) << message;
    EXPECT_EQ(readText(out), "theirs");
    EXPECT_EQ(entries(t.path), 1u);  // no temporary left
    // Through the file-name writers (VTK, images) too.
    const std::string other = t / "race2.ssvdag";
    ASSERT_EQ(refusal(other, {}, false), "");
    EXPECT_THROW(vdbdag::writeViaTemporary(other, [&](const std::string& tmp) {
        writeText(tmp, "ours");
        writeText(other, "theirs");
    }), vdbdag::Error);
    EXPECT_EQ(readText(other), "theirs");
    // --force: replacing is what the user asked for.
    const std::string forced = t / "forced.ssvdag";
    ASSERT_EQ(refusal(forced, {}, true), "");
    vdbdag::writeStreamAtomically(forced, [&](std::ostream& s) {
        s << "ours";
        writeText(forced, "theirs");
    });
    EXPECT_EQ(readText(forced), "ours");
}

TEST(TemporaryFiles, TemporaryNamesAreHiddenBesideTheOutputAndCarryThePid) {
    const std::string name = vdbdag::temporaryNameFor("/some/folder/out.vdb", ".png");
    const std::string expected = "/some/folder/.out.vdb.tmp." + std::to_string(getpid()) + ".";
    EXPECT_EQ(name.compare(0, expected.size(), expected), 0) << name;
    EXPECT_EQ(name.substr(name.size() - 4), ".png");
}

TEST(TemporaryFiles, RemoveAllRemovesRegisteredFilesAndFolders) {
    TempFolder t;
    writeText(t / "file.tmp", "x");
    fs::create_directories(t.path / "folder.tmp" / "pieces");
    writeText((t.path / "folder.tmp" / "a.vtu").string(), "a");
    writeText((t.path / "folder.tmp" / "pieces" / "b.vtu").string(), "b");
    writeText(t / "unregistered", "keep");
    {
        vdbdag::TemporaryGuard file(t / "file.tmp");
        vdbdag::TemporaryGuard folder(t / "folder.tmp", true);
        vdbdag::removeAllTemporaries();
    }
    EXPECT_FALSE(fs::exists(t / "file.tmp"));
    EXPECT_FALSE(fs::exists(t / "folder.tmp"));
    EXPECT_EQ(readText(t / "unregistered"), "keep");
    // A released guard is forgotten.
    writeText(t / "later.tmp", "x");
    { vdbdag::TemporaryGuard g(t / "later.tmp"); }
    vdbdag::removeAllTemporaries();
    EXPECT_TRUE(fs::exists(t / "later.tmp"));
}

TEST(TemporaryFiles, ATerminatedChildRemovesItsTemporaries) {
    TempFolder t;
    const std::string tmp = t / ".out.vdb.tmp.child";
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        vdbdag::installInterruptCleanup();
        writeText(tmp, "partial");
        vdbdag::TemporaryGuard guard(tmp);
        for (;;) pause();
    }
    for (int i = 0; i < 500 && !fs::exists(tmp); ++i) usleep(10000);
    usleep(50000);  // the guard is registered right after the file is written
    ASSERT_EQ(kill(child, SIGTERM), 0);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(WTERMSIG(status), SIGTERM);
    EXPECT_FALSE(fs::exists(tmp));
}

TEST(TemporaryFiles, StaleTemporariesOfDeadProcessesAreRemovedOnly) {
    TempFolder t;
    // A PID that surely has ended: a child we waited for.
    const pid_t dead = fork();
    if (dead == 0) _exit(0);
    waitpid(dead, nullptr, 0);
    const std::string stale = t / (".out.vdb.tmp." + std::to_string(dead) + ".123");
    const std::string live = t / (".out.vdb.tmp." + std::to_string(getppid()) + ".456");
    const std::string other = t / (".other.vdb.tmp." + std::to_string(dead) + ".789");
    writeText(stale, "s");
    writeText(live, "l");
    writeText(other, "o");
    fs::create_directory(t / (".out.vdb.tmp." + std::to_string(dead) + ".9"));
    vdbdag::removeStaleTemporaries(t / "out.vdb");
    EXPECT_FALSE(fs::exists(stale));
    EXPECT_FALSE(fs::exists(t / (".out.vdb.tmp." + std::to_string(dead) + ".9")));
    EXPECT_TRUE(fs::exists(live));
    EXPECT_TRUE(fs::exists(other));
}

// Out of memory is one line naming the file, exit 1, and no temporary left:
// never "terminate called" (OpenVDB's destructors allocate while a bad_alloc
// unwinds) and never a crash (c-blosc goes on with a null buffer when its
// posix_memalign fails). The address-space cap that makes a run fail depends
// on the machine, so caps are tried from small to large, every 20 MB, from
// the first at which the program starts at all (below it the libraries'
// own start-up fails) until one run succeeds; every run must end either
// well or with that one line.
TEST(OutOfMemory, IsOneLineNamingTheFileAndLeavesNothing) {
    const fs::path input = fs::path(VDBDAG_SHARED_DATA) / "levelsets" / "bunny_d512_ls.vdb";
    if (!fs::exists(input)) GTEST_SKIP() << "needs ../shared/data";
    TempFolder t;
    const std::string out = t / "out.ssvdag";
    bool sawOutOfMemory = false;
    int startMb = 300;
    while (startMb <= 1600 && std::system(("ulimit -v " + std::to_string(startMb * 1024) + "; exec " + std::string(VDBDAG_BINARY) +
                                           " --version > /dev/null 2>&1").c_str()) != 0)
        startMb += 20;
    // A margin above that: right at it, the libraries' start-up (280 shared
    // libraries) can still fail in their own static initialisers.
    for (int capMb = startMb + 40; capMb <= 1600; capMb += 20) {
        const std::string errFile = t / "err.txt";
        const int status = std::system(("ulimit -v " + std::to_string(capMb * 1024) + "; exec " + std::string(VDBDAG_BINARY) + " encode " +
                                        input.string() + " -o " + out + " -f > /dev/null 2> " + errFile)
                                           .c_str());
        const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        const std::string err = readText(errFile);
        fs::remove(errFile);
        if (code == 127) continue;  // the dynamic loader itself did not fit
        EXPECT_EQ(err.find("terminate called"), std::string::npos) << capMb << " MB: " << err;
        if (code == 0) break;  // fits: larger caps will too
        EXPECT_EQ(code, 1) << capMb << " MB: " << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << capMb << " MB: " << err;
        EXPECT_NE(err.find(input.string() + ": out of memory while encoding"), std::string::npos) << capMb << " MB: " << err;
        sawOutOfMemory = true;
        EXPECT_FALSE(fs::exists(out)) << capMb << " MB";
        EXPECT_EQ(entries(t.path), 0u) << "a temporary was left behind";
    }
    if (!sawOutOfMemory) GTEST_SKIP() << "no cap up to 1.6 GB made the encode run out of memory here";
}
